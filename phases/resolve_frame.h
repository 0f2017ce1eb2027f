// resolve_frame.h -- what a band of SampleLayout::resolve (sample_pattern.h) reads and
// writes, for the builds of resolve_rows.h.
#pragma once

#include <cstddef>
#include <cstdint>

namespace mpshade {

// What a band of the resolve reads and writes: the frame's per-sample RGBA, the layout's
// weights (SampleLayout's members of the same names) and the output pixels.
struct ResolveFrame {
    const float* rgba = nullptr;
    const uint8_t* uniform = nullptr;  // per pixel, may be null
    float* pixels = nullptr;           // RGBA, width x height
    const float* weights = nullptr;
    const float* pixelWeights = nullptr;
    const float* blockWeights = nullptr;
    const float* inverseSum = nullptr;
    int width = 0, height = 0, reach = 1;
    size_t taps = 3, spp = 1;
    bool blocks = false;  // look for 2x2 blocks of alike pixels (shaded per 2x2 pixels)
};

}  // namespace mpshade
