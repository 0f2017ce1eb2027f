#include "geometry/chart_adjacency.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

namespace mpshade {
namespace {

// The point at distance `along` (0..1, from the edge's first corner) on edge e, `in` inside.
void edgePoint(int e, float along, float in, float& u, float& v) {
    switch (e) {
        case 0:
            u = along, v = in;
            break;
        case 1:
            u = 1.0f - in, v = along;
            break;
        case 2:
            u = 1.0f - along, v = 1.0f - in;
            break;
        default:
            u = in, v = 1.0f - along;
            break;
    }
}

}  // namespace

ChartAdjacency::ChartAdjacency(const Surface& surface) {
    const int charts = chartCount(surface);
    links_.assign(static_cast<size_t>(charts), {});
    const float tolerance = 1e-5f * std::max(surfaceBounds(surface).diagonal(), 1e-30f);
    // Quantized positions of the corners and midpoints: keys for matching.
    using Key = std::tuple<long, long, long>;
    auto keyOf = [&](const glm::vec3& p) {
        return Key{std::lround(p.x / tolerance), std::lround(p.y / tolerance),
                   std::lround(p.z / tolerance)};
    };
    std::map<std::tuple<Key, Key, Key>, std::vector<std::pair<int, int>>> edges;
    for (int chart = 0; chart < charts; ++chart) {
        for (int e = 0; e < 4; ++e) {
            float u0, v0, um, vm, u1, v1;
            edgePoint(e, 0.0f, 0.0f, u0, v0);
            edgePoint(e, 0.5f, 0.0f, um, vm);
            edgePoint(e, 1.0f, 0.0f, u1, v1);
            Key a = keyOf(evaluate(surface, {chart, u0, v0}).P);
            const Key m = keyOf(evaluate(surface, {chart, um, vm}).P);
            Key b = keyOf(evaluate(surface, {chart, u1, v1}).P);
            if (a == b && a == m) continue;  // collapsed (a pole): no neighbour across it
            if (b < a) std::swap(a, b);
            edges[{a, m, b}].push_back({chart, e});
        }
    }
    // Rounding can split one point over neighbouring keys; those edges simply stay unlinked
    // and clamp, which is what happened before adjacency existed.
    for (const auto& [key, sides] : edges) {
        if (sides.size() != 2) continue;
        const auto [c0, e0] = sides[0];
        const auto [c1, e1] = sides[1];
        // Same direction if the points a quarter along both edges coincide (the end points
        // alone cannot tell for an edge that closes on itself, like a torus's seam).
        float ua, va, ub, vb;
        edgePoint(e0, 0.25f, 0.0f, ua, va);
        edgePoint(e1, 0.25f, 0.0f, ub, vb);
        const bool same =
            keyOf(evaluate(surface, {c0, ua, va}).P) == keyOf(evaluate(surface, {c1, ub, vb}).P);
        links_[static_cast<size_t>(c0)][static_cast<size_t>(e0)] = {c1, e1, !same};
        links_[static_cast<size_t>(c1)][static_cast<size_t>(e1)] = {c0, e0, !same};
    }
}

ChartPoint ChartAdjacency::resolve(int chart, float u, float v) const {
    if (u >= 0.0f && u <= 1.0f && v >= 0.0f && v <= 1.0f) return {chart, u, v};
    // The edge crossed most, how far along it, and how far beyond.
    const float over[4] = {-v, u - 1.0f, v - 1.0f, -u};
    int e = 0;
    for (int k = 1; k < 4; ++k)
        if (over[k] > over[e]) e = k;
    const float cu = std::clamp(u, 0.0f, 1.0f), cv = std::clamp(v, 0.0f, 1.0f);
    const float along = e == 0 ? cu : e == 1 ? cv : e == 2 ? 1.0f - cu : 1.0f - cv;
    const ChartEdgeLink& l = link(chart, e);
    if (l.chart < 0) return {chart, cu, cv};
    float nu, nv;
    edgePoint(l.edge, l.reversed ? 1.0f - along : along, over[e], nu, nv);
    return {l.chart, std::clamp(nu, 0.0f, 1.0f), std::clamp(nv, 0.0f, 1.0f)};
}

}  // namespace mpshade
