#include "shadermaps/chart_aspect.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace mpshade {

ChartShifts chartShifts(const Surface& surface, int maxShift) {
    const int charts = chartCount(surface);
    ChartShifts s;
    s.u.assign(static_cast<size_t>(std::max(charts, 0)), 0);
    s.v.assign(s.u.size(), 0);
    maxShift = std::clamp(maxShift, 0, kMaxChartShift);
    if (charts > kMaxAspectCharts || maxShift == 0) return s;
    constexpr int kGrid = 4;
    std::vector<ChartPoint> points;
    points.reserve(static_cast<size_t>(charts) * kGrid * kGrid);
    for (int c = 0; c < charts; ++c)
        for (int j = 0; j < kGrid; ++j)
            for (int i = 0; i < kGrid; ++i)
                points.push_back({c, (static_cast<float>(i) + 0.5f) / kGrid,
                                  (static_cast<float>(j) + 0.5f) / kGrid});
    std::vector<SurfaceSample> g(points.size());
    evaluateBatch(surface, points, g);
    for (int c = 0; c < charts; ++c) {
        double weight = 0.0, sum = 0.0;
        for (int k = 0; k < kGrid * kGrid; ++k) {
            const SurfaceSample& x = g[static_cast<size_t>(c) * kGrid * kGrid + k];
            const double a = glm::length(x.dPdu), b = glm::length(x.dPdv);
            const double area = glm::length(glm::cross(x.dPdu, x.dPdv));
            // A degenerate point (a pole, a collapsed edge) says nothing of the chart's shape.
            if (!(a > 0.0 && b > 0.0 && area > 0.0 && std::isfinite(a / b) && std::isfinite(area)))
                continue;
            weight += area;
            sum += area * std::log2(a / b);
        }
        if (!(weight > 0.0)) continue;
        const double mean = sum / weight;
        const int shift = static_cast<int>(
            std::clamp(std::floor(std::fabs(mean)), 0.0, static_cast<double>(maxShift)));
        // u longer on the surface than v: v needs fewer texels, and the other way round.
        (mean > 0.0 ? s.v : s.u)[static_cast<size_t>(c)] = static_cast<uint8_t>(shift);
    }
    return s;
}

double coarseLevelTiles(const ChartShifts& shifts, int resolution, int tileSize, int levels) {
    int all = 0;
    while ((resolution >> all) > 1) ++all;
    ++all;  // 1 x 1 included
    double tiles = 0.0;
    for (size_t c = 0; c < shifts.u.size(); ++c)
        for (int level = std::max(0, all - levels); level < all; ++level) {
            const auto along = [&](int shift) {
                const int res = std::max(1, resolution >> std::min(level + shift, 30));
                return (res + tileSize - 1) / tileSize;
            };
            tiles += static_cast<double>(along(shifts.u[c])) * along(shifts.v[c]);
        }
    return tiles;
}

}  // namespace mpshade
