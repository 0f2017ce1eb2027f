#include "phases/sample_pattern.h"

#include <cmath>

#include <tbb/parallel_for.h>

namespace mpshade {
namespace {

uint32_t mix32(uint32_t h) {
    h ^= h >> 16;
    h *= 0x7feb352du;
    h ^= h >> 15;
    h *= 0x846ca68bu;
    h ^= h >> 16;
    return h;
}

}  // namespace

void samplePosition(uint32_t seed, int px, int py, int k, int spp, float& x, float& y) {
    const int nx = static_cast<int>(std::ceil(std::sqrt(static_cast<float>(spp))));
    const int ny = (spp + nx - 1) / nx;
    uint32_t h = mix32(seed ^ 0x9e3779b9u);
    h = mix32(h ^ static_cast<uint32_t>(px) * 0x85ebca6bu);
    h = mix32(h ^ static_cast<uint32_t>(py) * 0xc2b2ae35u);
    h = mix32(h ^ static_cast<uint32_t>(k) * 0x27d4eb2fu);
    const float jx = static_cast<float>(h & 0xFFFFu) * (1.0f / 65536.0f);
    const float jy = static_cast<float>(h >> 16) * (1.0f / 65536.0f);
    x = static_cast<float>(px) + (static_cast<float>(k % nx) + jx) / static_cast<float>(nx);
    y = static_cast<float>(py) + (static_cast<float>(k / nx) + jy) / static_cast<float>(ny);
}

void SampleBuffer::resize(int w, int h, int samplesPerPixel) {
    width = w;
    height = h;
    spp = samplesPerPixel;
    const size_t n = static_cast<size_t>(w) * h * samplesPerPixel;
    xy.assign(n * 2, 0.0f);
    rgba.assign(n * 4, 0.0f);
}

Image resolvePixels(const SampleBuffer& samples, const PixelFilter& filter) {
    Image image(samples.width, samples.height);
    const float inv2s2 = 1.0f / (2.0f * filter.sigma * filter.sigma);
    const float tail = std::exp(-filter.radius * filter.radius * inv2s2);
    const int reach = static_cast<int>(std::ceil(filter.radius));
    tbb::parallel_for(0, samples.height, [&](int py) {
        for (int px = 0; px < samples.width; ++px) {
            const float cx = static_cast<float>(px) + 0.5f, cy = static_cast<float>(py) + 0.5f;
            double sum[4] = {0, 0, 0, 0}, weight = 0.0;
            for (int qy = std::max(0, py - reach); qy <= std::min(samples.height - 1, py + reach);
                 ++qy) {
                for (int qx = std::max(0, px - reach);
                     qx <= std::min(samples.width - 1, px + reach); ++qx) {
                    for (int k = 0; k < samples.spp; ++k) {
                        const size_t i = samples.index(qx, qy, k);
                        const float dx = std::fabs(samples.xy[2 * i] - cx);
                        const float dy = std::fabs(samples.xy[2 * i + 1] - cy);
                        if (dx >= filter.radius || dy >= filter.radius) continue;
                        const float w = std::max(0.0f, std::exp(-dx * dx * inv2s2) - tail) *
                                        std::max(0.0f, std::exp(-dy * dy * inv2s2) - tail);
                        for (int c = 0; c < 4; ++c) sum[c] += w * samples.rgba[4 * i + c];
                        weight += w;
                    }
                }
            }
            float* out = image.pixel(px, py);
            for (int c = 0; c < 4; ++c)
                out[c] = weight > 0.0 ? static_cast<float>(sum[c] / weight) : 0.0f;
        }
    });
    return image;
}

}  // namespace mpshade
