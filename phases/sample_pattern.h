// sample_pattern.h -- where the sub-pixel samples of a frame lie, and how they become pixels.
// Every renderer (reference and multi-phase) uses these, so images differ only by how
// each sample's color was computed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "phases/image.h"

namespace mpshade {

// Sample k (of spp) of pixel (px, py): stratified jittered. The pixel is cut into an
// nx x ny grid (nx = ceil(sqrt(spp)), ny = ceil(spp / nx)); sample k takes cell
// (k mod nx, k div nx) and a hashed offset inside it, so positions depend only on
// (seed, px, py, k). Returns image coordinates in pixels (continuous, y down).
void samplePosition(uint32_t seed, int px, int py, int k, int spp, float& x, float& y);

// Per-sample results of one frame: sample k of pixel (px, py) at index
// (py * width + px) * spp + k.
struct SampleBuffer {
    int width = 0, height = 0, spp = 1;
    std::vector<float> xy;    // 2 floats per sample: image position
    std::vector<float> rgba;  // 4 floats per sample: composited color over the background, alpha

    void resize(int w, int h, int samplesPerPixel);
    size_t index(int px, int py, int k) const {
        return (static_cast<size_t>(py) * width + px) * spp + k;
    }
};

// The pixel reconstruction filter: a truncated Gaussian (pbrt-v4's GaussianFilter),
// f(d) = max(0, exp(-d^2 / (2 sigma^2)) - exp(-r^2 / (2 sigma^2))) separably in x and y.
struct PixelFilter {
    float radius = 1.5f;  // pixels
    float sigma = 0.5f;   // pixels
};

// Each pixel is the filter-weighted mean of the samples within `radius` of its centre.
Image resolvePixels(const SampleBuffer& samples, const PixelFilter& filter);

}  // namespace mpshade
