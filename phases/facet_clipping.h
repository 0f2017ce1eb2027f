// facet_clipping.h -- facets that cross the near plane or the guard band, clipped in
// homogeneous screen coordinates (Sutherland and Hodgman 1974) into screen triangles.
//
// Facets only as fine as the geometric error allows can be large: a ground plane is two
// triangles, and the camera stands on it. Such a facet has corners behind the eye or far
// outside the screen, which the warp cannot project; the rasterizer clips it against
// W >= near and |X|, |Y| <= 2^15 W (the warp's own culling planes), then fans the
// polygon into triangles.
//
// Watertight: a corner the warp kept keeps its warped position; a new corner, where an
// edge crosses a plane, is computed from the edge's two end points taken in a canonical
// order (by their coordinates), so the two facets sharing an edge make the same corner
// bit for bit, and the same rounding to the 1/256-pixel grid.
#pragma once

#include <cstdint>

#include "phases/fixed_point_warp.h"

namespace mpshade {

// A triangle on the screen: 1/256-pixel corners and 1 / view depth at each.
struct ScreenTriangle {
    int32_t x[3], y[3];
    float invDepth[3];
};

// Clips facet corners p[0..2] (position indices into the warped vertices, at least one
// culled by the warp) and writes up to 6 screen triangles to `out`, in fan order; returns
// how many. Zero when nothing of the facet is in front of the near plane and inside the
// guard band.
int clipFacet(const FixedPointWarp& warp, const FacetMesh& mesh, const WarpedVertices& warped,
              const uint32_t p[3], ScreenTriangle out[6]);

}  // namespace mpshade
