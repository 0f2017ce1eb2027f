#include "phases/image_compare.h"

#include <algorithm>
#include <cmath>

#include "geometry/error.h"

namespace mpshade {

ImageError compareImages(const Image& test, const Image& reference) {
    MPSHADE_CHECK(test.width == reference.width && test.height == reference.height);
    ImageError e;
    double sum = 0.0, alpha = 0.0;
    const size_t pixels = static_cast<size_t>(test.width) * test.height;
    for (size_t i = 0; i < pixels; ++i) {
        for (int c = 0; c < 3; ++c) {
            const double a = std::clamp(test.rgba[4 * i + c], 0.0f, 1.0f);
            const double b = std::clamp(reference.rgba[4 * i + c], 0.0f, 1.0f);
            sum += (a - b) * (a - b);
            e.maxAbs = std::max(e.maxAbs, std::fabs(a - b));
        }
        alpha += std::fabs(static_cast<double>(test.rgba[4 * i + 3]) - reference.rgba[4 * i + 3]);
    }
    const double mse = pixels > 0 ? sum / (3.0 * pixels) : 0.0;
    e.rmse = std::sqrt(mse);
    e.psnr = mse > 0.0 ? std::min(99.0, 10.0 * std::log10(1.0 / mse)) : 99.0;
    e.coverageDiff = pixels > 0 ? alpha / pixels : 0.0;
    return e;
}

Image differenceImage(const Image& test, const Image& reference, float gain) {
    MPSHADE_CHECK(test.width == reference.width && test.height == reference.height);
    Image out(test.width, test.height);
    const size_t pixels = static_cast<size_t>(test.width) * test.height;
    for (size_t i = 0; i < pixels; ++i) {
        for (int c = 0; c < 3; ++c)
            out.rgba[4 * i + c] =
                gain * std::fabs(std::clamp(test.rgba[4 * i + c], 0.0f, 1.0f) -
                                 std::clamp(reference.rgba[4 * i + c], 0.0f, 1.0f));
        out.rgba[4 * i + 3] = 1.0f;
    }
    return out;
}

}  // namespace mpshade
