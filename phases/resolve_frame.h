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
    // RGBA output: image pixel (px, py) at pixels + 4 * ((py - y0) * stride + px - x0). The
    // whole image: x0 = y0 = 0, stride = width.
    float* pixels = nullptr;
    int x0 = 0, y0 = 0, stride = 0;
    // The image columns whose samples are read, [col0, col1) (col0 even where blocks are
    // looked for: a block is met at its left column); the whole image: 0, width. Writes
    // reach `reach` columns (with blocks, reach + 1 to the right) beyond them: the window
    // above must hold those columns.
    int col0 = 0, col1 = 0;
    const float* weights = nullptr;
    const float* pixelWeights = nullptr;
    const float* blockWeights = nullptr;
    const float* inverseSum = nullptr;
    int width = 0, height = 0, reach = 1;
    size_t taps = 3, spp = 1;
    bool blocks = false;  // look for 2x2 blocks of alike pixels (shaded per 2x2 pixels)
};

}  // namespace mpshade
