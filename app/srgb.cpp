#include "app/srgb.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

namespace mpshade {
namespace {

// thresholds[k]: the least float c >= 0 whose code is at least k (k >= 1); [0] is unused
// and [256] is past every float. The code never decreases as c grows, so a bisection over
// the bit patterns of the floats in [0, 1] (ordered as integers) finds each step.
//
// first[b]: the code at the start of bucket b, the floats of [0, 1] cut by their top bits
// (exponent and 8 bits of mantissa) from 2^-13 up, everything below in bucket 0. A bucket
// spans at most 0.4% of its values while a code's step spans at least 0.9% (near 1.0, where
// 255 sRGB(c) rises fastest relative to c: 112 codes per unit), and all of bucket 0 is code 0
// (255 * 12.92 * 2^-13 * (1 + 2^-8) = 0.40); so a bucket holds at most one step, and the
// code is first[b] or the one after it. A table look-up and one comparison, no branches:
// the bisection's eight unpredictable branches had been most of writing a PNG frame.
constexpr uint32_t kBucketBits = 15;                        // of the float's 23
constexpr uint32_t kBucketBase = uint32_t{127 - 13} << 23;  // 2^-13
constexpr uint32_t kBuckets = ((uint32_t{127} << 23) - kBucketBase) >> kBucketBits;  // to 1.0

struct SrgbSteps {
    float thresholds[257] = {};
    uint8_t first[kBuckets + 1] = {};
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
        thresholds[256] = std::numeric_limits<float>::infinity();
        for (uint32_t b = 0; b <= kBuckets; ++b)
            first[b] = srgbCodeDirect(
                b == 0 ? 0.0f : std::bit_cast<float>(kBucketBase + (b << kBucketBits)));
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
    c = c > 0.0f ? std::min(c, 1.0f) : 0.0f;  // NaN to 0
    const uint32_t bits = std::bit_cast<uint32_t>(c);
    const uint32_t bucket = bits < kBucketBase ? 0 : (bits - kBucketBase) >> kBucketBits;
    const uint8_t k = steps.first[bucket];
    return static_cast<uint8_t>(k + (c >= steps.thresholds[k + 1] ? 1 : 0));
}

}  // namespace mpshade
