// point_cloud.h -- oriented discs ("points"), one chart per point.
//
// File format: one "x y z nx ny nz radius" per line; '#' starts a comment. The normal need
// not be unit length but must not be zero; the radius must be positive.
// Chart k is disc k in polar form: (u, v) -> centre + u * radius * (cos 2 pi v T + sin 2 pi v B),
// with (T, B, N) a fixed orthonormal frame built from the normal.
#pragma once

#include <string>
#include <vector>

#include "geometry/surface_sample.h"

namespace mpshade {

struct PointCloud {
    std::vector<glm::vec3> centers;
    std::vector<glm::vec3> normals;  // unit
    std::vector<float> radii;        // > 0

    int chartCount() const { return static_cast<int>(centers.size()); }
    SurfaceSample evaluate(int chart, float u, float v) const;
    Bounds3 bounds() const;
    int tessellationRate(int chart) const { return 0; }  // traced as Embree discs
    // Chart (u, v) of an object-space point on disc `chart` (inverse of evaluate).
    ChartPoint chartPointOf(int chart, const glm::vec3& p) const;
};

PointCloud loadPointCloud(const std::string& path);

// A right-handed orthonormal frame (T, B) around unit n (Duff et al. 2017).
void orthonormalBasis(const glm::vec3& n, glm::vec3& T, glm::vec3& B);

}  // namespace mpshade
