// The NaN policy over rows of results (sanitizeShadeRows) against the one-result policy
// (sanitizeShade), which says it with std::isfinite and std::clamp: the same bits and the
// same count, for every batch length's vector part and tail, with NaN, infinities,
// negative and above-one opacities, -0 and denormals in any component.
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "phases/compositing.h"
#include "test_support.h"

namespace mpshade {
namespace {

// Floats equal bit for bit, or, with denormals flushed, both denormal or zero: a path
// that only copies a denormal keeps it where one that computes with it reads zero.
bool sameResult(float a, float b, bool flushing) {
    if (std::memcmp(&a, &b, sizeof a) == 0) return true;
    return flushing && std::fabs(a) < std::numeric_limits<float>::min() &&
           std::fabs(b) < std::numeric_limits<float>::min();
}

// The policy is checked with denormals kept and flushed (test::FloatMode): the renderer's
// shading tasks flush them, and a test run before this one may have left either mode.
TEST(Compositing, RowsAreSanitizedAsEachResultAlone) {
    for (const bool flushing : {false, true}) {
        SCOPED_TRACE(flushing ? "denormals flushed" : "IEEE denormals");
        const test::FloatMode mode(flushing);
        std::mt19937 rng(5);
        const float specials[] = {std::numeric_limits<float>::quiet_NaN(),
                                  std::numeric_limits<float>::infinity(),
                                  -std::numeric_limits<float>::infinity(),
                                  -0.0f,
                                  1e-40f,
                                  -2.5f,
                                  1.0f,
                                  0.0f,
                                  7.0f};
        std::uniform_real_distribution<float> value(-0.5f, 1.5f);
        std::uniform_int_distribution<int> pick(0, 19);
        for (size_t n = 0; n <= 13; ++n)
            for (int trial = 0; trial < 40; ++trial) {
                std::vector<float> rows(6 * n);
                for (float& x : rows) {
                    const int p = pick(rng);
                    x = p < 9 ? specials[p] : value(rng);
                }
                const float* r = rows.data();
                const float* ci[3] = {r, r + n, r + 2 * n};
                const float* oi[3] = {r + 3 * n, r + 4 * n, r + 5 * n};
                std::vector<float> color(3 * n + 1, 42.0f), opacity(3 * n + 1, 42.0f);
                const size_t bad = sanitizeShadeRows(n, ci, oi, color.data(), opacity.data());
                size_t expectBad = 0;
                for (size_t i = 0; i < n; ++i) {
                    float c[3] = {ci[0][i], ci[1][i], ci[2][i]},
                          o[3] = {oi[0][i], oi[1][i], oi[2][i]};
                    if (!sanitizeShade(c, o)) ++expectBad;
                    for (int k = 0; k < 3; ++k) {
                        ASSERT_TRUE(sameResult(color[3 * i + k], c[k], flushing))
                            << "n " << n << " result " << i << " colour " << k;
                        ASSERT_TRUE(sameResult(opacity[3 * i + k], o[k], flushing))
                            << "n " << n << " result " << i << " opacity " << k;
                    }
                }
                EXPECT_EQ(bad, expectBad) << "n " << n;
                // Nothing written past the last result.
                EXPECT_EQ(color[3 * n], 42.0f);
                EXPECT_EQ(opacity[3 * n], 42.0f);
            }
    }
}

}  // namespace
}  // namespace mpshade
