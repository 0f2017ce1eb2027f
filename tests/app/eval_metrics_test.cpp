// The arithmetic of `mpshade eval`, against numbers worked out by hand.
#include "app/eval_metrics.h"

#include <cmath>

#include <gtest/gtest.h>

namespace mpshade {
namespace {

Image onePixel(float r, float g, float b) {
    Image image(1, 1);
    image.rgba = {r, g, b, 1.0f};
    return image;
}

TEST(EvalMetrics, PsnrOfMse) {
    EXPECT_DOUBLE_EQ(psnrOfMse(0.01), 20.0);
    EXPECT_DOUBLE_EQ(psnrOfMse(1e-4), 40.0);
    EXPECT_TRUE(std::isinf(psnrOfMse(0.0)));
    EXPECT_GT(psnrOfMse(0.0), 0.0);
}

TEST(EvalMetrics, MeanSquaredErrorClampsEachChannel) {
    // 1.5 counts as 1 and -1 as 0: differences 0.5, -0.2 and 0.
    const double mse = meanSquaredError(onePixel(1.5f, 0.2f, -1.0f), onePixel(0.5f, 0.4f, 0.0f));
    EXPECT_NEAR(mse, (0.25 + 0.04) / 3.0, 1e-7);
    const Image a = onePixel(0.3f, 0.6f, 0.9f);
    EXPECT_EQ(meanSquaredError(a, a), 0.0);
}

TEST(EvalMetrics, TemporalErrorIsTheChangeNotTheLevel) {
    // A test image off by a constant but moving exactly as the truth: no temporal error.
    EXPECT_NEAR(temporalRmse(onePixel(0.1f, 0.1f, 0.1f), onePixel(0.4f, 0.3f, 0.2f),
                             onePixel(0.2f, 0.2f, 0.2f), onePixel(0.5f, 0.4f, 0.3f)),
                0.0, 1e-7);
    // A frozen test image while the truth brightens by 0.3: 0.3 in every channel.
    const Image still = onePixel(0.5f, 0.5f, 0.5f);
    EXPECT_NEAR(temporalRmse(still, still, onePixel(0.2f, 0.2f, 0.2f), onePixel(0.5f, 0.5f, 0.5f)),
                0.3, 1e-6);
    // Flicker against a still truth: changes of 0.2, 0 and -0.2 give sqrt(0.08 / 3).
    EXPECT_NEAR(temporalRmse(onePixel(0.4f, 0.5f, 0.6f), onePixel(0.6f, 0.5f, 0.4f), still, still),
                std::sqrt(0.08 / 3.0), 1e-6);
}

TEST(EvalMetrics, ParetoFrontKeepsOnlyUnbeatenPoints) {
    const std::vector<TimedError> points = {{1.0, 30.0}, {2.0, 35.0},      {1.5, 29.0}, {3.0, 34.0},
                                            {2.0, 36.0}, {INFINITY, 50.0}, {0.5, 30.0}};
    // (0.5, 30) beats (1, 30); (2, 36) beats (2, 35) at the same time; (3, 34) and
    // (1.5, 29) are beaten; an infinite time is left out.
    const std::vector<size_t> front = paretoFront(points);
    ASSERT_EQ(front.size(), 2u);
    EXPECT_EQ(front[0], 6u);
    EXPECT_EQ(front[1], 4u);
    // Along a front, time and PSNR both rise.
    const std::vector<TimedError> ladder = {{4, 36}, {1, 30}, {2, 33}};
    const std::vector<size_t> sorted = paretoFront(ladder);
    ASSERT_EQ(sorted.size(), 3u);
    for (size_t k = 1; k < sorted.size(); ++k) {
        EXPECT_GT(ladder[sorted[k]].seconds, ladder[sorted[k - 1]].seconds);
        EXPECT_GT(ladder[sorted[k]].psnr, ladder[sorted[k - 1]].psnr);
    }
}

TEST(EvalMetrics, TimeAtPsnrInterpolatesLogTimeLinearlyInDecibels) {
    const std::vector<TimedError> ladder = {{1.0, 30.0}, {2.0, 33.0}, {4.0, 36.0}};
    LadderTime t = timeAtPsnr(ladder, 31.5);
    ASSERT_TRUE(t.valid);
    EXPECT_NEAR(t.seconds, std::sqrt(2.0), 1e-12);
    EXPECT_FALSE(t.extrapolated);
    t = timeAtPsnr(ladder, 33.0);  // exactly on a rung
    EXPECT_NEAR(t.seconds, 2.0, 1e-12);
    EXPECT_FALSE(t.extrapolated);
    t = timeAtPsnr(ladder, 36.0);  // the last rung: not beyond it
    EXPECT_NEAR(t.seconds, 4.0, 1e-12);
    EXPECT_FALSE(t.extrapolated);
    // Beyond: the last segment extended, 3 dB more per doubling.
    t = timeAtPsnr(ladder, 39.0);
    EXPECT_NEAR(t.seconds, 8.0, 1e-9);
    EXPECT_TRUE(t.extrapolated);
    // Below the first rung: its time, marked.
    t = timeAtPsnr(ladder, 29.0);
    EXPECT_DOUBLE_EQ(t.seconds, 1.0);
    EXPECT_TRUE(t.extrapolated);
    // A beaten rung is not interpolated through: (3 s, 31 dB) is off the front.
    const std::vector<TimedError> withSlow = {{1.0, 30.0}, {3.0, 31.0}, {2.0, 33.0}};
    EXPECT_NEAR(timeAtPsnr(withSlow, 31.5).seconds, std::sqrt(2.0), 1e-12);
    EXPECT_FALSE(timeAtPsnr({{1.0, 30.0}}, 30.0).valid);
}

TEST(EvalMetrics, AtTheFrontsFirstRungItsOwnTimeExactly) {
    // Exactly at the first rung's PSNR: that rung's time as measured, not one interpolated
    // to it through logarithms (2^log2(0.05) is not 0.05 in doubles), and not marked.
    const std::vector<TimedError> ladder = {{0.05, 30.0}, {0.4, 33.0}};
    const LadderTime t = timeAtPsnr(ladder, 30.0);
    ASSERT_TRUE(t.valid);
    EXPECT_EQ(t.seconds, 0.05);
    EXPECT_FALSE(t.extrapolated);
}

}  // namespace
}  // namespace mpshade
