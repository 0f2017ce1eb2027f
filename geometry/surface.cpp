#include "geometry/surface.h"

#include "geometry/error.h"

namespace mpshade {

const char* surfaceTypeName(const Surface& surface) {
    static constexpr const char* kNames[] = {"sphere", "torus", "plane", "bezier",
                                             "subdiv", "mesh",  "points"};
    return kNames[surface.index()];
}

int chartCount(const Surface& surface) {
    return std::visit([](const auto& s) { return s.chartCount(); }, surface);
}

Bounds3 surfaceBounds(const Surface& surface) {
    return std::visit([](const auto& s) { return s.bounds(); }, surface);
}

SurfaceSample evaluate(const Surface& surface, ChartPoint at) {
    return std::visit([&](const auto& s) { return s.evaluate(at.chart, at.u, at.v); }, surface);
}

bool isClosed(const Surface& surface) {
    if (std::holds_alternative<Sphere>(surface) || std::holds_alternative<Torus>(surface))
        return true;
    if (const auto* s = std::get_if<SubdivSurface>(&surface)) return s->closed();
    if (const auto* m = std::get_if<PolygonMesh>(&surface)) return m->closed();
    return false;  // planes, Bezier patch sets, points
}

void evaluateBatch(const Surface& surface, std::span<const ChartPoint> points,
                   std::span<SurfaceSample> out) {
    MPSHADE_CHECK(points.size() == out.size());
    std::visit(
        [&](const auto& s) {
            for (size_t i = 0; i < points.size(); ++i)
                out[i] = s.evaluate(points[i].chart, points[i].u, points[i].v);
        },
        surface);
}

}  // namespace mpshade
