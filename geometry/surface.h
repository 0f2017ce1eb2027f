// surface.h -- the closed set of surface types, dispatched once per batch with std::visit.
#pragma once

#include <span>
#include <variant>

#include "geometry/analytic_shapes.h"
#include "geometry/bezier_patches.h"
#include "geometry/point_cloud.h"
#include "geometry/polygon_mesh.h"
#include "geometry/subdiv_surface.h"

namespace mpshade {

using Surface =
    std::variant<Sphere, Torus, Plane, BezierPatches, SubdivSurface, PolygonMesh, PointCloud>;

// The scene-format name of the type ("sphere", "subdiv", ...).
const char* surfaceTypeName(const Surface& surface);
int chartCount(const Surface& surface);
Bounds3 surfaceBounds(const Surface& surface);
SurfaceSample evaluate(const Surface& surface, ChartPoint at);
// The surface bounds a solid, so only its outside can be seen.
bool isClosed(const Surface& surface);
// Evaluates points.size() chart points into out (same size), one dispatch for the batch.
void evaluateBatch(const Surface& surface, std::span<const ChartPoint> points,
                   std::span<SurfaceSample> out);

}  // namespace mpshade
