// Frame-rate-locked frames: the dynamic phase never waits, static work takes the time
// left, and with time enough a frame is the constant-quality frame exactly.
#include <cmath>

#include <gtest/gtest.h>

#include "controller/playback.h"
#include "scene/scene.h"
#include "test_support.h"

namespace mpshade {
namespace {

MultiphaseOptions budgeted(double seconds, double minimumShare) {
    MultiphaseOptions o;
    o.staticPhase.shaderMap.fillPinnedUpFront = true;
    o.singlePhaseFrames = false;
    o.frameBudgetSeconds = seconds;
    o.minimumStaticShare = minimumShare;
    return o;
}

RenderOptions small() {
    RenderOptions r;
    r.width = 96;
    r.height = 54;
    return r;
}

double coverage(const Image& image) {
    double c = 0.0;
    for (size_t p = 3; p < image.rgba.size(); p += 4) c += image.rgba[p];
    return c / (image.width * image.height);
}

TEST(Playback, WithTimeEnoughAFrameIsTheConstantQualityFrame) {
    const Scene scene = loadScene(test::sourcePath("examples/vase/scene.json"));
    MultiphaseRenderer play(scene, budgeted(60.0, 0.1));
    FrameStats first, second;
    const Image coarse = play.renderFrame(3, small(), first);
    // The first frame fell back (its maps held only their coarsest levels), then filled
    // every tile it lacked in the time left.
    EXPECT_GT(first.probeFallbacks, 0u);
    EXPECT_GT(first.tilesRequested, 0u);
    EXPECT_EQ(first.tilesDeferred, 0u);
    EXPECT_TRUE(first.deadlineMet);
    EXPECT_EQ(first.budgetSeconds, 60.0);
    const Image fine = play.renderFrame(3, small(), second);
    EXPECT_EQ(second.probeFallbacks, 0u);
    EXPECT_EQ(second.tilesRequested, 0u);

    MultiphaseOptions constant;
    constant.singlePhaseFrames = false;
    MultiphaseRenderer render(scene, constant);
    FrameStats stats;
    const Image reference = render.renderFrame(3, small(), stats);
    ASSERT_EQ(fine.rgba.size(), reference.rgba.size());
    EXPECT_EQ(fine.rgba, reference.rgba);  // the image does not depend on history
    EXPECT_NE(coarse.rgba, reference.rgba);
}

TEST(Playback, NoTimeLeftDefersTilesAndRebuildsButDrawsEveryFrame) {
    const Scene scene = loadScene(test::sourcePath("examples/vase/scene.json"));
    // A budget nothing fits: after the first frame (whose objects must be built), no tile is
    // filled and no rebuild is run, yet every frame is drawn, from the coarser levels.
    MultiphaseRenderer play(scene, budgeted(1e-6, 0.0));
    FrameStats stats;
    play.renderFrame(3, small(), stats);
    EXPECT_EQ(stats.staticRuns, 2);  // never built: built whatever the budget
    EXPECT_FALSE(stats.deadlineMet);
    for (int frame : {4, 40}) {  // 40: the camera has orbited out of the vase's range
        SCOPED_TRACE(frame);
        const Image image = play.renderFrame(frame, small(), stats);
        EXPECT_EQ(stats.staticRuns, 0);
        EXPECT_EQ(stats.tilesFilled, 0u);
        EXPECT_GT(stats.tilesRequested, 0u);
        EXPECT_EQ(stats.tilesDeferred, stats.tilesRequested);
        EXPECT_GT(stats.probeFallbacks, 0u);
        if (frame == 40) {
            EXPECT_GE(stats.rebuildsDeferred, 1);
        }
        for (float v : image.rgba) ASSERT_TRUE(std::isfinite(v));
        EXPECT_GT(coverage(image), 0.3);
    }
}

TEST(Playback, PlaysEveryFrameAndRegulatesTheShadingRate) {
    const Scene scene = loadScene(test::sourcePath("examples/teapot/scene.json"));
    PlaybackOptions options;
    options.render = small();
    options.first = 0;
    options.last = 4;
    // A rate no frame can meet: the regulator must move to per-pixel shading at once.
    options.fps = 1e6;
    std::vector<ShadingRate> rates;
    int frames = 0;
    const PlaybackSummary summary =
        playScene(scene, options, [&](const FrameStats& s, const Image& image, ShadingRate r) {
            EXPECT_EQ(s.index, options.first + frames);
            EXPECT_DOUBLE_EQ(s.budgetSeconds, 1e-6);
            EXPECT_EQ(image.width, 96);
            rates.push_back(r);
            ++frames;
        });
    EXPECT_EQ(summary.frames, 4);
    EXPECT_EQ(summary.deadlinesMet, 0);
    EXPECT_GT(summary.prerollSeconds, 0.0);
    ASSERT_EQ(rates.size(), 4u);
    EXPECT_EQ(rates[0], ShadingRate::Sample);  // the scene's
    for (size_t k = 1; k < rates.size(); ++k) EXPECT_EQ(rates[k], ShadingRate::Pixel);
}

}  // namespace
}  // namespace mpshade
