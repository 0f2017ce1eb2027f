// image.h -- a linear RGBA float image, rows top to bottom.
#pragma once

#include <cstddef>
#include <vector>

namespace mpshade {

// A rectangle of image pixels: columns [x0, x1), rows [y0, y1).
struct PixelRect {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    int area() const { return (x1 - x0) * (y1 - y0); }
};

struct Image {
    int width = 0, height = 0;
    std::vector<float> rgba;  // 4 floats per pixel, row-major, linear, alpha = coverage

    Image() = default;
    Image(int w, int h) : width(w), height(h), rgba(static_cast<size_t>(w) * h * 4, 0.0f) {}
    float* pixel(int x, int y) { return &rgba[(static_cast<size_t>(y) * width + x) * 4]; }
    const float* pixel(int x, int y) const {
        return &rgba[(static_cast<size_t>(y) * width + x) * 4];
    }
};

}  // namespace mpshade
