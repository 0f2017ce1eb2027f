#include "controller/quality_regulator.h"

#include <gtest/gtest.h>

namespace mpshade {
namespace {

// A frame whose dynamic phase took `rest` seconds outside shading and `shade` shading.
FrameStats frame(double rest, double shade = 0.0) {
    FrameStats s;
    s.dynamic.warpSeconds = 0.25 * rest;
    s.dynamic.rasterSeconds = 0.5 * rest;
    s.dynamic.resolveSeconds = 0.25 * rest;
    s.dynamic.shadeSeconds = shade;
    return s;
}

// Shares exact in binary, so the tests can sit on their boundaries: a step down above 3/4
// of the budget, a step up predicted below 1/2, a start within 5/8.
QualityRegulatorOptions exactShares() {
    QualityRegulatorOptions o;
    o.slowDownAt = 0.75;
    o.dropAt = 0.875;
    o.speedUpAt = 0.5;
    return o;
}

TEST(QualityRegulator, TheLadderStartsAtTheScenesRate) {
    const QualityRegulator fromSample(ShadingRate::Sample, 4);
    ASSERT_EQ(fromSample.levels(), 7);
    EXPECT_EQ(fromSample.step().rate, ShadingRate::Sample);
    EXPECT_EQ(fromSample.step().footprintScale, 1.0f);
    EXPECT_EQ(fromSample.step(2).rate, ShadingRate::Pixel);
    EXPECT_EQ(fromSample.step(2).footprintScale, 2.0f);
    EXPECT_EQ(fromSample.step(4).rate, ShadingRate::Quad);
    EXPECT_EQ(fromSample.step(4).footprintScale, 2.0f);
    EXPECT_EQ(fromSample.step(4).samplesPerPixel, 0);  // the request's
    EXPECT_EQ(fromSample.step(5).samplesPerPixel, 2);
    EXPECT_EQ(fromSample.step(6).samplesPerPixel, 1);
    EXPECT_EQ(fromSample.step(6).rate, ShadingRate::Quad);
    const QualityRegulator fromPixel(ShadingRate::Pixel, 4);
    EXPECT_EQ(fromPixel.levels(), 6);
    EXPECT_EQ(fromPixel.step().rate, ShadingRate::Pixel);
    const QualityRegulator fromQuad(ShadingRate::Quad, 2);
    EXPECT_EQ(fromQuad.levels(), 3);  // samples per pixel halved once: to one
    EXPECT_EQ(fromQuad.step().rate, ShadingRate::Quad);
    EXPECT_EQ(QualityRegulator(ShadingRate::Sample, 1).levels(), 5);
}

TEST(QualityRegulator, BeforeMeasuringTheRatiosAreTheShadingPoints) {
    const QualityRegulator r(ShadingRate::Sample, 8);
    ASSERT_EQ(r.levels(), 7);
    EXPECT_EQ(r.costRatioAbove(1), 8.0);  // per sample over per pixel
    EXPECT_EQ(r.costRatioAbove(2), 1.0);  // the footprint alone differs
    EXPECT_EQ(r.costRatioAbove(3), 4.0);  // per pixel over per 2x2 pixels
    EXPECT_EQ(r.costRatioAbove(4), 1.0);
    EXPECT_EQ(r.costRatioAbove(5), 1.0);  // fewer samples: not a shading-point count
}

TEST(QualityRegulator, StepsDownOnlyAboveItsShareAndStopsAtTheBottom) {
    QualityRegulator r(ShadingRate::Sample, 1, exactShares());  // five steps
    r.update(frame(0.5, 0.25), 1.0);  // exactly at the share is not above it
    r.update(frame(0.5, 0.25), 1.0);
    EXPECT_EQ(r.level(), 0);
    r.update(frame(0.5, 0.2501), 1.0);  // one frame above: the machine, maybe
    EXPECT_EQ(r.level(), 0);
    r.update(frame(0.5, 0.2), 1.0);  // back under: the count starts again
    r.update(frame(0.5, 0.2501), 1.0);
    EXPECT_EQ(r.level(), 0);
    r.update(frame(0.5, 0.2501), 1.0);  // two in a row
    EXPECT_EQ(r.level(), 1);
    EXPECT_EQ(r.step().rate, ShadingRate::Pixel);
    r.update(frame(0.5, 0.375), 1.0);  // exactly at dropAt: not above it
    EXPECT_EQ(r.level(), 1);
    r.update(frame(0.5, 0.3751), 1.0);  // above dropAt: at once
    EXPECT_EQ(r.level(), 2);
    for (int k = 0; k < 10; ++k) r.update(frame(2.0, 2.0), 1.0);
    EXPECT_EQ(r.level(), 4);
}

TEST(QualityRegulator, StartsAtTheBestStepItsCalibrationFits) {
    QualityRegulator fits(ShadingRate::Sample, 1, exactShares());  // five steps
    const double atTarget[] = {0.625, 0.5, 0.25, 0.125, 0.0625};
    fits.calibrate(atTarget, 1.0);
    EXPECT_EQ(fits.level(), 0);
    EXPECT_EQ(fits.costRatioAbove(1), 1.25);
    EXPECT_EQ(fits.costRatioAbove(2), 2.0);
    QualityRegulator perPixel(ShadingRate::Sample, 1, exactShares());
    const double justAbove[] = {0.626, 0.625, 0.5, 0.25, 0.5};  // the last: noise
    perPixel.calibrate(justAbove, 1.0);
    EXPECT_EQ(perPixel.level(), 1);
    EXPECT_EQ(perPixel.costRatioAbove(4), 1.0);  // a lower step costing more counts as equal
    QualityRegulator none(ShadingRate::Sample, 1, exactShares());
    const double late[] = {4.0, 2.0, 1.0, 0.75, 0.7};
    none.calibrate(late, 1.0);
    EXPECT_EQ(none.level(), 4);
}

TEST(QualityRegulator, RefinedStepsGetTheirShareOfTheBudget) {
    // Seven steps at 4 spp; refinement gives the steps it refines (1 to 3) half the shares,
    // the best step (nothing to refine) and the last at 4 spp (below it only fewer samples)
    // the whole of them: the start is within 5/8 there, 5/16 at steps 1 to 3.
    QualityRegulatorOptions o = exactShares();
    o.refinedShare = 0.5;
    const double bestFits[] = {0.625, 0.3125, 0.3, 0.2, 0.1, 0.05, 0.025};
    QualityRegulator best(ShadingRate::Sample, 4, o);
    best.calibrate(bestFits, 1.0);
    EXPECT_EQ(best.level(), 0);
    const double thirdFits[] = {0.7, 0.4, 0.35, 0.3125, 0.1, 0.05, 0.025};
    QualityRegulator third(ShadingRate::Sample, 4, o);
    third.calibrate(thirdFits, 1.0);
    EXPECT_EQ(third.level(), 3);  // step 1 would fit the whole share, not its half
    const double lastFullFits[] = {0.7, 0.5, 0.45, 0.4, 0.625, 0.2, 0.1};
    QualityRegulator lastFull(ShadingRate::Sample, 4, o);
    lastFull.calibrate(lastFullFits, 1.0);
    EXPECT_EQ(lastFull.level(), 4);  // not the 2 spp below it
    // At step 3, frames over half of slowDownAt (3/8) twice in a row step down; a frame
    // under it does not.
    third.update(frame(0.375, 0.0), 1.0);
    third.update(frame(0.375, 0.0), 1.0);
    EXPECT_EQ(third.level(), 3);
    third.update(frame(0.376, 0.0), 1.0);
    third.update(frame(0.376, 0.0), 1.0);
    EXPECT_EQ(third.level(), 4);
}

TEST(QualityRegulator, StepsUpAfterCalmFramesPredictingTheStepAboveFits) {
    QualityRegulator r(ShadingRate::Sample, 1, exactShares());  // five steps; calmFrames 8
    const double seconds[] = {1.0, 0.5, 0.375, 0.25, 0.125};
    r.calibrate(seconds, 1.0);
    ASSERT_EQ(r.level(), 1);
    ASSERT_EQ(r.costRatioAbove(1), 2.0);
    // 0.25 x 2 is exactly the share: does not fit (for fewer than probeFrames, 16).
    for (int k = 0; k < 15; ++k) r.update(frame(0.25), 1.0);
    EXPECT_EQ(r.level(), 1);
    for (int k = 0; k < 7; ++k) r.update(frame(0.24), 1.0);
    EXPECT_EQ(r.level(), 1);
    r.update(frame(0.25), 1.0);  // one that does not fit starts the count again
    for (int k = 0; k < 7; ++k) r.update(frame(0.24), 1.0);
    EXPECT_EQ(r.level(), 1);
    r.update(frame(0.24), 1.0);
    EXPECT_EQ(r.level(), 0);
    // The first frame on the step above measures the ratio again: 0.6 / 0.24.
    r.update(frame(0.6), 1.0);
    EXPECT_EQ(r.level(), 0);
    EXPECT_DOUBLE_EQ(r.costRatioAbove(1), 2.5);
}

TEST(QualityRegulator, TriesTheStepAboveWhenItsRatioMayBeStale) {
    // A step down measured on a slow frame: 0.9 at level 0, then 0.3 at level 1, a ratio of
    // 3 (the true one is 1.25). Predicted 0.3 x 3 = 0.9 >= dropAt: never tried.
    QualityRegulator r(ShadingRate::Pixel, 1, exactShares());  // four steps
    r.update(frame(0.9), 1.0);
    ASSERT_EQ(r.level(), 1);
    r.update(frame(0.3), 1.0);
    ASSERT_DOUBLE_EQ(r.costRatioAbove(1), 3.0);
    for (int k = 0; k < 40; ++k) r.update(frame(0.3), 1.0);
    EXPECT_EQ(r.level(), 1);
    // Faster frames predict 0.28 x 3 = 0.84: over speedUpAt, under dropAt. After 16 of them
    // in a row (one that predicts dropAt or more starts the count again), level 0 is tried.
    for (int k = 0; k < 15; ++k) r.update(frame(0.28), 1.0);
    EXPECT_EQ(r.level(), 1);
    r.update(frame(0.3), 1.0);
    for (int k = 0; k < 15; ++k) r.update(frame(0.28), 1.0);
    EXPECT_EQ(r.level(), 1);
    r.update(frame(0.28), 1.0);
    EXPECT_EQ(r.level(), 0);
    // Its true cost, 0.35, measures the ratio again and keeps the step.
    r.update(frame(0.35), 1.0);
    EXPECT_DOUBLE_EQ(r.costRatioAbove(1), 0.35 / 0.28);
    for (int k = 0; k < 20; ++k) r.update(frame(0.35), 1.0);
    EXPECT_EQ(r.level(), 0);
}

TEST(QualityRegulator, ATriedStepThatIsTooSlowIsLeftAgain) {
    QualityRegulator r(ShadingRate::Pixel, 1, exactShares());
    r.update(frame(0.9), 1.0);
    r.update(frame(0.4), 1.0);  // ratio 2.25: 0.4 x 2.25 = 0.9, not tried
    ASSERT_EQ(r.level(), 1);
    for (int k = 0; k < 16; ++k) r.update(frame(0.375), 1.0);  // 0.84375: tried
    ASSERT_EQ(r.level(), 0);
    // Truly 0.8 (over slowDownAt, under dropAt: on time): two such frames step down.
    r.update(frame(0.8), 1.0);
    EXPECT_EQ(r.level(), 0);
    r.update(frame(0.8), 1.0);
    EXPECT_EQ(r.level(), 1);
}

TEST(QualityRegulator, AStepDownMeasuresTheRatioOfTheTwoSteps) {
    QualityRegulator r(ShadingRate::Pixel, 1, exactShares());
    r.update(frame(0.9), 1.0);  // above dropAt: to level 1
    ASSERT_EQ(r.level(), 1);
    r.update(frame(0.225), 1.0);
    EXPECT_DOUBLE_EQ(r.costRatioAbove(1), 4.0);
    EXPECT_EQ(r.costRatioAbove(2), 4.0);  // not measured: the points' ratio
}

TEST(QualityRegulator, AStillViewsReplaysPredictFromTheLastFreshFrame) {
    // At level 1 a fresh frame of 0.45 (x2 = 0.9: the step above would be late), then
    // replays of 0.1 (x2 = 0.2 would fit): the step above's first frame is fresh, so it is
    // neither stepped up to nor tried, and no ratio is measured between the fresh frame and
    // the replays.
    QualityRegulator r(ShadingRate::Sample, 1, exactShares());
    const double seconds[] = {1.0, 0.5, 0.375, 0.25, 0.125};
    r.calibrate(seconds, 1.0);
    ASSERT_EQ(r.level(), 1);
    r.update(frame(0.45), 1.0);
    FrameStats replay = frame(0.1);
    replay.dynamic.viewReused = true;
    for (int k = 0; k < 40; ++k) r.update(replay, 1.0);
    EXPECT_EQ(r.level(), 1);
    EXPECT_DOUBLE_EQ(r.costRatioAbove(1), 2.0);
    // A fresh frame at 0.24 (x2 fits) and its replays: up after the calm frames. The first
    // frame there, fresh, measures no ratio against the replay before it.
    r.update(frame(0.24), 1.0);
    for (int k = 0; k < 7; ++k) r.update(replay, 1.0);
    EXPECT_EQ(r.level(), 0);
    r.update(frame(0.3), 1.0);
    EXPECT_DOUBLE_EQ(r.costRatioAbove(1), 2.0);  // unchanged: 0.3 against a replay
}

}  // namespace
}  // namespace mpshade
