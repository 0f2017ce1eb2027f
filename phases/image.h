// image.h -- a linear RGBA float image, rows top to bottom.
#pragma once

#include <cstddef>
#include <vector>

namespace mpshade {

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
