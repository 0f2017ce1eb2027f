#include "phases/shading_cost_image.h"

#include <algorithm>
#include <numeric>

namespace mpshade {

double ShadingCostImage::totalPoints() const {
    return std::accumulate(objectPoints.begin(), objectPoints.end(), 0.0);
}

double ShadingCostImage::totalCost() const {
    return std::accumulate(objectCost.begin(), objectCost.end(), 0.0);
}

ShadingCostImage shadingCostImage(const SampleLayout& layout, const VisibilityBuffer& vis,
                                  const BandPointOptions& options,
                                  std::span<const float> costPerPoint) {
    ShadingCostImage out;
    if (vis.width != layout.width() || vis.height != layout.height() || vis.spp != layout.spp() ||
        layout.width() <= 0 || layout.height() <= 0)
        return out;
    out.width = layout.width();
    out.height = layout.height();
    const size_t pixels = static_cast<size_t>(out.width) * out.height;
    out.points.assign(pixels, 0.0f);
    out.cost.assign(pixels, 0.0f);
    size_t objects = costPerPoint.size();
    for (size_t s = 0; s < vis.count.size(); ++s)
        for (int l = 0; l < vis.count[s]; ++l)
            objects = std::max(objects, size_t{vis.object[s * vis.layers + l]} + 1);
    out.objectPoints.assign(objects, 0.0);
    out.objectCost.assign(objects, 0.0);
    // The whole image as one band: it starts at row 0, so 2x2 blocks fall as the dynamic
    // phase's bands (an even number of rows each) make them.
    const BandRange range(layout, vis.layers, 0, layout.height());
    BandPoints points;
    BandPointScratch scratch;
    buildBandPoints(layout, vis, range, objects, options, points, scratch);
    // A point is shared among the pixels whose samples composite it (a 2x2 block's, at
    // per-block shading), each pixel taking its samples' share: the totals are the points
    // shaded, and no point lands in a pixel that does not use it (a point's position, on the
    // rasterizer's 1/256-pixel grid, may round onto the next pixel's edge).
    const int spp = layout.spp(), layers = vis.layers;
    auto forEachUse = [&](auto&& use) {
        for (size_t pixel = 0; pixel < pixels; ++pixel) {
            if (!points.pixelPoint.empty() && points.pixelPoint[pixel] != kNoPoint) {
                use(pixel, points.pixelPoint[pixel], static_cast<float>(spp));
                continue;
            }
            for (size_t smp = pixel * spp; smp < (pixel + 1) * spp; ++smp)
                for (int l = 0; l < vis.count[smp]; ++l)
                    if (const uint32_t p = points.fragmentPoint[smp * layers + l]; p != kNoPoint)
                        use(pixel, p, 1.0f);
        }
    };
    std::vector<float> uses(points.object.size(), 0.0f);
    forEachUse([&](size_t, uint32_t p, float n) { uses[p] += n; });
    forEachUse([&](size_t pixel, uint32_t p, float n) {
        const float share = n / uses[p];
        const uint32_t o = points.object[p];
        const float c = o < costPerPoint.size() ? costPerPoint[o] : 0.0f;
        out.points[pixel] += share;
        out.cost[pixel] += share * c;
        out.objectPoints[o] += share;
        out.objectCost[o] += share * c;
    });
    return out;
}

}  // namespace mpshade
