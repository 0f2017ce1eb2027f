#include "app/srgb.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace mpshade {
namespace {

// thresholds[k]: the least float c >= 0 whose code is at least k (k >= 1); [0] is unused.
// The code never decreases as c grows, so a bisection over the bit patterns of the floats
// in [0, 1] (ordered as integers) finds each step.
struct SrgbSteps {
    float thresholds[256] = {};
    SrgbSteps() {
        const uint32_t top = std::bit_cast<uint32_t>(1.0f);
        for (int k = 1; k < 256; ++k) {
            uint32_t lo = 0, hi = top;  // code(lo) < k <= code(hi)
            while (hi - lo > 1) {
                const uint32_t mid = lo + (hi - lo) / 2;
                (srgbCodeDirect(std::bit_cast<float>(mid)) >= k ? hi : lo) = mid;
            }
            thresholds[k] = std::bit_cast<float>(hi);
        }
    }
};

}  // namespace

uint8_t srgbCodeDirect(float c) {
    c = c > 0.0f ? std::min(c, 1.0f) : 0.0f;  // NaN to 0
    const float s = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
    return static_cast<uint8_t>(std::lround(255.0f * s));
}

uint8_t srgbCode(float c) {
    static const SrgbSteps steps;
    // The largest k with thresholds[k] <= c; a NaN compares false throughout: 0.
    int k = 0;
    for (int step = 128; step > 0; step >>= 1)
        if (steps.thresholds[k + step] <= c) k += step;
    return static_cast<uint8_t>(k);
}

}  // namespace mpshade
