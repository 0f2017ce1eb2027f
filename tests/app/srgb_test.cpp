// The PNG frames' 8-bit sRGB codes: the step table against the transfer function, at every
// step's boundary and across the floats of [0, 1].
#include <bit>
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "app/srgb.h"

namespace mpshade {
namespace {

TEST(SrgbCode, KnownValues) {
    // round(255 sRGB(c)), worked in double precision: 0.18 -> 117.646, 0.5 -> 187.516,
    // 0.002 (linear segment) -> 6.589, 0.0031308 -> 10.315, 0.9 -> 243.445.
    EXPECT_EQ(srgbCode(0.18f), 118);
    EXPECT_EQ(srgbCode(0.5f), 188);
    EXPECT_EQ(srgbCode(0.002f), 7);
    EXPECT_EQ(srgbCode(0.0031308f), 10);
    EXPECT_EQ(srgbCode(0.9f), 243);
    EXPECT_EQ(srgbCode(0.0f), 0);
    EXPECT_EQ(srgbCode(1.0f), 255);
    EXPECT_EQ(srgbCode(7.5f), 255);
    EXPECT_EQ(srgbCode(std::numeric_limits<float>::infinity()), 255);
    EXPECT_EQ(srgbCode(-0.25f), 0);
    EXPECT_EQ(srgbCode(std::numeric_limits<float>::quiet_NaN()), 0);
}

TEST(SrgbCode, EqualsTheTransferFunctionAtEveryStepAndBetween) {
    // Each code's first float, found by bisection on the transfer function, and the float
    // just below it.
    const uint32_t top = std::bit_cast<uint32_t>(1.0f);
    for (int k = 1; k < 256; ++k) {
        uint32_t lo = 0, hi = top;
        while (hi - lo > 1) {
            const uint32_t mid = lo + (hi - lo) / 2;
            (srgbCodeDirect(std::bit_cast<float>(mid)) >= k ? hi : lo) = mid;
        }
        ASSERT_EQ(srgbCode(std::bit_cast<float>(hi)), k);
        ASSERT_EQ(srgbCode(std::bit_cast<float>(hi - 1)), k - 1);
    }
    // And a spread of the floats in [0, 1] (every 97th bit pattern: 11 million).
    for (uint32_t b = 0; b <= top; b += 97) {
        const float c = std::bit_cast<float>(b);
        ASSERT_EQ(srgbCode(c), srgbCodeDirect(c)) << c;
    }
}

}  // namespace
}  // namespace mpshade
