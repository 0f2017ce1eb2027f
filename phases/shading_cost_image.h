// shading_cost_image.h -- where a frame's dynamic shading went, per pixel: the shading
// points its dynamic phase made there and what running the dynamic shader on them costs,
// for an author to see which parts of the image the per-frame work is spent on
// (`mpshade render --cost-images`, docs/factoring.md).
#pragma once

#include <span>
#include <vector>

#include "phases/band_points.h"
#include "phases/facet_rasterizer.h"
#include "phases/sample_pattern.h"

namespace mpshade {

struct ShadingCostImage {
    int width = 0, height = 0;  // pixels; 0 when there is nothing to show
    // Per pixel, row-major: the shading points its samples composite, and their cost (each
    // point its object's costPerPoint). A point several pixels share (a 2x2 block's) is
    // divided among them by samples. Per sample, a pixel one surface covers holds spp
    // points; per pixel, 1; per 2x2 pixels, 1/4.
    std::vector<float> points, cost;
    std::vector<double> objectPoints, objectCost;  // per object, summed over the image
    double totalPoints() const;
    double totalCost() const;
};

// The points the dynamic phase makes from visibility buffer `vis` (band_points.h, the same
// function and options, so the same points) counted per pixel. costPerPoint: per scene
// object, in opCost units (shading/factoring.h: the dynamic part's cost, or the whole
// shader's for a direct representation); an object outside it costs 0.
ShadingCostImage shadingCostImage(const SampleLayout& layout, const VisibilityBuffer& vis,
                                  const BandPointOptions& options,
                                  std::span<const float> costPerPoint);

}  // namespace mpshade
