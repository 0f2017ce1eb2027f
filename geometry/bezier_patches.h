// bezier_patches.h -- bicubic Bezier patches, one chart per patch.
//
// File format (the classic Newell teapot layout): the patch count; per patch 16 one-based
// control-point indices separated by commas and/or white space, row-major with u running
// fastest; the vertex count; one "x y z" per vertex. Lines starting with '#' are comments.
// A patch's chart is its own (u, v) domain.
#pragma once

#include <string>
#include <vector>

#include "geometry/surface_sample.h"

namespace mpshade {

struct BezierPatches {
    // 16 control points per patch, row-major (index = 4 * row(v) + column(u)).
    std::vector<glm::vec3> controlPoints;
    // The normal is cross(dPdu, dPdv); at collapsed edges, its limit from inside the patch.
    int chartCount() const { return static_cast<int>(controlPoints.size() / 16); }
    SurfaceSample evaluate(int chart, float u, float v) const;
    Bounds3 bounds() const;
    int tessellationRate(int chart) const { return 32; }
};

// Loads a patch file; throws InputError naming file:line for malformed content.
BezierPatches loadBezierPatches(const std::string& path);

}  // namespace mpshade
