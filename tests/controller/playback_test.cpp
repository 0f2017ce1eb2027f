// Frame-rate-locked frames: the dynamic phase never waits, static work takes the time
// left, and with time enough a frame is the constant-quality frame exactly.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>

#include "controller/playback.h"
#include "phases/image_compare.h"
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
    // every tile it found missing in the time left.
    EXPECT_GT(first.dynamic.probeFallbacks, 0u);
    EXPECT_GT(first.tiles.missing, 0u);
    EXPECT_EQ(first.budget.tilesDeferred, 0u);
    EXPECT_TRUE(first.budget.deadlineMet);
    EXPECT_EQ(first.budget.seconds, 60.0);
    const Image fine = play.renderFrame(3, small(), second);
    EXPECT_EQ(second.dynamic.probeFallbacks, 0u);
    EXPECT_EQ(second.tiles.missing, 0u);

    MultiphaseOptions constant;
    constant.singlePhaseFrames = false;
    // A renderer with a budget measures no footprints (playback measures them before it
    // sets one): uniform ones here too.
    constant.footprints.enabled = false;
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
    EXPECT_EQ(stats.staticWork.work.runs, 2);  // never built: built whatever the budget
    EXPECT_FALSE(stats.budget.deadlineMet);
    for (int frame : {4, 40}) {  // 40: the camera has orbited out of the vase's range
        SCOPED_TRACE(frame);
        const Image image = play.renderFrame(frame, small(), stats);
        EXPECT_EQ(stats.staticWork.work.runs, 0);
        EXPECT_EQ(stats.staticWork.work.tilesFilled, 0u);
        EXPECT_GT(stats.tiles.missing, 0u);
        EXPECT_EQ(stats.budget.tilesDeferred, stats.tiles.missing);
        EXPECT_GT(stats.dynamic.probeFallbacks, 0u);
        if (frame == 40) {
            EXPECT_GE(stats.budget.rebuildsDeferred, 1);
        }
        for (float v : image.rgba) ASSERT_TRUE(std::isfinite(v));
        EXPECT_GT(coverage(image), 0.3);
    }
}

TEST(Playback, ARebuildIsPricedWithoutTheMapItKeeps) {
    // A frame budget admits a rebuild by what it should cost. The first build of a map object
    // made its map (its always-resident levels filled, most of that build's time); a rebuild
    // re-dices and keeps the map, so that part is not its price. Priced with it, the
    // courtyard's columns (first builds 100-150 ms, rebuilds 4-18) were deferred for good in
    // `play` and drawn from facets diced for a view 40 degrees away.
    const Scene scene = loadScene(test::sourcePath("examples/vase/scene.json"));
    MultiphaseRenderer play(scene, budgeted(60.0, 0.1));
    FrameStats stats;
    play.renderFrame(3, small(), stats);
    const ObjectSlot& vase = play.slot(0);
    ASSERT_EQ(vase.kind, Representation::ShaderMap);
    const StaticCosts first = vase.report.staticCosts;
    ASSERT_EQ(first.runs, 1);
    EXPECT_GT(first.keptMapSeconds, 0.0);
    EXPECT_LT(first.keptMapSeconds, first.seconds);
    EXPECT_DOUBLE_EQ(vase.rebuildSeconds, first.seconds - first.keptMapSeconds);
    play.renderFrame(40, small(), stats);  // the camera has orbited out of the vase's range
    ASSERT_EQ(vase.report.staticCosts.runs, 2);
    EXPECT_EQ(vase.report.staticCosts.keptMapSeconds, first.keptMapSeconds);  // the map was kept
    EXPECT_NEAR(vase.rebuildSeconds, vase.report.staticCosts.seconds - first.seconds, 1e-12);
}

TEST(Playback, ARebuildForANewViewIsMadeInTheBackgroundAndTakenUpAfter) {
    const Scene scene = loadScene(test::sourcePath("examples/vase/scene.json"));
    MultiphaseOptions o = budgeted(60.0, 0.1);
    o.directWhenSlower = false;  // the floor's choice would depend on the frames' history
    o.backgroundRebuilds = true;
    o.backgroundIdlePriority = false;  // waited on below, whatever else loads the machine
    MultiphaseRenderer play(scene, o);
    FrameStats stats;
    play.renderFrame(3, small(), stats);
    EXPECT_EQ(stats.staticWork.work.runs, 2);  // first builds: in the frame, whatever the option
    const ObjectRepresentation* before = play.representation(0);
    // The camera has orbited out of the vase's range: its re-dice goes to the worker, and
    // the frame draws the vase as it was, though the budget had time for the rebuild.
    play.renderFrame(40, small(), stats);
    EXPECT_GE(stats.budget.rebuildsInBackground, 1);
    EXPECT_EQ(stats.budget.rebuildsDeferred, stats.budget.rebuildsInBackground);
    EXPECT_EQ(stats.staticWork.work.runs, 0);
    EXPECT_EQ(play.representation(0), before);
    EXPECT_EQ(play.slot(0).report.staticCosts.runs, 1);
    play.waitForBackgroundRebuilds();
    EXPECT_TRUE(play.rebuildingInBackground(0));  // done, not yet taken up
    const Image image = play.renderFrame(40, small(), stats);
    EXPECT_GE(stats.background.rebuilds, 1);
    EXPECT_GT(stats.background.rebuildSeconds, 0.0);
    EXPECT_FALSE(play.rebuildingInBackground(0));
    for (const StaticRunDue& d : stats.staticWork.due) EXPECT_NE(d.object, 0u);
    ASSERT_NE(play.representation(0), before);
    EXPECT_EQ(play.slot(0).report.staticCosts.runs, 2);
    EXPECT_GT(play.slot(0).rebuildSeconds, 0.0);

    // The same representation and, once its tiles are filled, the same frame as a renderer
    // that rebuilt the vase in the frame that found it due.
    o.backgroundRebuilds = false;
    MultiphaseRenderer inFrame(scene, o);
    FrameStats s;
    inFrame.renderFrame(3, small(), s);
    inFrame.renderFrame(40, small(), s);
    ASSERT_EQ(s.staticWork.work.runs, stats.background.rebuilds);
    const ObjectRepresentation& a = *play.representation(0);
    const ObjectRepresentation& b = *inFrame.representation(0);
    EXPECT_EQ(a.representativeEye, b.representativeEye);
    EXPECT_EQ(a.mesh.facetCount(), b.mesh.facetCount());
    EXPECT_EQ(a.bytes(), b.bytes());
    EXPECT_EQ(a.map == nullptr, b.map == nullptr);
    EXPECT_EQ(a.mesh.qx, b.mesh.qx);
    EXPECT_EQ(a.mesh.qy, b.mesh.qy);
    EXPECT_EQ(a.mesh.qz, b.mesh.qz);
    EXPECT_EQ(a.mesh.positionIndex, b.mesh.positionIndex);
    EXPECT_EQ(image.rgba, inFrame.renderFrame(40, small(), s).rgba);
}

TEST(Playback, DiscardingStaticWorkDropsTheRebuildsInTheBackground) {
    const Scene scene = loadScene(test::sourcePath("examples/vase/scene.json"));
    MultiphaseOptions o = budgeted(60.0, 0.1);
    o.backgroundRebuilds = true;
    MultiphaseRenderer play(scene, o);
    FrameStats stats;
    play.renderFrame(3, small(), stats);
    play.renderFrame(40, small(), stats);
    ASSERT_TRUE(play.rebuildingInBackground(0));
    play.discardStaticWork();  // whether the rebuild was under way, done or still queued
    EXPECT_FALSE(play.rebuildingInBackground(0));
    EXPECT_EQ(play.representation(0), nullptr);
    const Image image = play.renderFrame(40, small(), stats);
    EXPECT_EQ(stats.staticWork.work.runs, 2);  // built again, in the frame
    EXPECT_EQ(stats.background.rebuilds, 0);
    EXPECT_GT(coverage(image), 0.3);
}

TEST(Playback, DeferredTilesAreFilledInTheBackgroundForTheNextFrames) {
    const Scene scene = loadScene(test::sourcePath("examples/vase/scene.json"));
    // No time for fills in any frame: what frame 4 found missing goes to the background filler,
    // which fills it while nothing else runs; frame 4 again then finds missing nothing, and is the
    // constant-quality frame (from objects built for the same views).
    MultiphaseOptions o = budgeted(1e-6, 0.0);
    o.backgroundFills = true;
    o.backgroundIdlePriority = false;  // waited on below, whatever else loads the machine
    MultiphaseRenderer play(scene, o);
    FrameStats stats;
    play.renderFrame(3, small(), stats);
    play.renderFrame(4, small(), stats);
    const uint64_t deferred = stats.budget.tilesDeferred;
    ASSERT_GT(deferred, 20u);
    for (int wait = 0; wait < 6000 && play.backgroundQueued() > 0; ++wait)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    ASSERT_EQ(play.backgroundQueued(), 0u);
    const Image image = play.renderFrame(4, small(), stats);
    // At least those (the worker may also have filled some of frame 3's queue meanwhile).
    EXPECT_GE(stats.background.tilesFilled, deferred);
    EXPECT_EQ(stats.tiles.missing, 0u);
    EXPECT_EQ(stats.dynamic.probeFallbacks, 0u);
    MultiphaseOptions constant;
    constant.singlePhaseFrames = false;
    // A renderer with a budget measures no footprints (playback measures them before it
    // sets one): uniform ones here too.
    constant.footprints.enabled = false;
    MultiphaseRenderer reference(scene, constant);
    FrameStats cs;
    reference.renderFrame(3, small(), cs);  // the same views built
    EXPECT_GT(compareImages(image, reference.renderFrame(4, small(), cs)).psnr, 60.0);
}

TEST(Playback, ThePrerollMeasuresFootprintsAndTheFramesPlayAtThem) {
    const Scene scene = loadScene(test::sourcePath("examples/vase/scene.json"));
    PlaybackOptions options;
    options.render = small();
    options.first = 0;
    options.last = 24;  // enough frames to repay the measuring (minFrames)
    options.fps = 0.5;  // time enough: frames at constant quality
    Image played;
    const PlaybackSummary summary = playScene(
        scene, options, [&](const FrameStats& s, const Image& image, const PlaybackQuality&) {
            played = image;
            return s.index < 2;
        });
    ASSERT_EQ(summary.objectFootprints.size(), scene.objects.size());
    float widest = 1.0f;
    for (float f : summary.objectFootprints) widest = std::max(widest, f);
    EXPECT_GT(widest, 1.0f);  // the floor's static part is smooth at this size

    MultiphaseOptions constant;
    constant.singlePhaseFrames = false;
    constant.footprints.enabled = false;
    constant.dynamic.objectFootprint = summary.objectFootprints;
    MultiphaseRenderer told(scene, constant);
    FrameStats cs;
    for (int f = 0; f < 2; ++f) told.renderFrame(f, small(), cs);
    const Image want = told.renderFrame(2, small(), cs);
    EXPECT_GT(compareImages(played, want).psnr, 60.0);
    constant.dynamic.objectFootprint = {};
    MultiphaseRenderer uniform(scene, constant);
    for (int f = 0; f < 2; ++f) uniform.renderFrame(f, small(), cs);
    EXPECT_LT(compareImages(played, uniform.renderFrame(2, small(), cs)).psnr, 60.0);
}

TEST(Playback, TheLadderIsMeasuredWithTheTilesOfEachStepFilled) {
    // A floor seen at grazing angles reads levels far finer than the always-resident ones:
    // each coarser step reads a level the steps before it had not filled, and measured at
    // once its probes fell back (a slower path: per pixel at 1280x720 had been priced
    // above per 2x2 pixels).
    const Scene scene = loadScene(test::sourcePath("examples/hard/grazing_floor.json"));
    PlaybackOptions options;
    options.render = small();
    options.render.width = 192;
    options.render.height = 108;
    options.first = 0;
    options.last = 1;
    options.prefetch = false;
    const PlaybackSummary summary =
        playScene(scene, options,
                  [&](const FrameStats&, const Image&, const PlaybackQuality&) { return true; });
    ASSERT_GE(summary.steps.size(), 5u);
    for (const PlaybackStep& p : summary.steps) EXPECT_EQ(p.probeFallbacks, 0u);
}

TEST(Playback, CalibratesEachStepOnTheLeastOfItsMeasurements) {
    const Scene scene = loadScene(test::sourcePath("examples/teapot/scene.json"));
    for (const int frames : {1, 3}) {
        PlaybackOptions options;
        options.render = small();
        options.first = 0;
        options.last = 1;
        options.calibrationFrames = frames;
        const PlaybackSummary summary =
            playScene(scene, options,
                      [](const FrameStats&, const Image&, const PlaybackQuality&) { return true; });
        ASSERT_EQ(summary.steps.size(), 7u);
        for (const PlaybackStep& step : summary.steps) {
            ASSERT_EQ(step.measuredSeconds.size(), static_cast<size_t>(frames));
            for (const double s : step.measuredSeconds) EXPECT_GT(s, 0.0);
            // The regulator is given the least: not the first, the last or a mean.
            EXPECT_EQ(step.dynamicSeconds,
                      *std::min_element(step.measuredSeconds.begin(), step.measuredSeconds.end()));
        }
    }
}

TEST(Playback, PlaysEveryFrameAndRegulatesItsQuality) {
    const Scene scene = loadScene(test::sourcePath("examples/teapot/scene.json"));
    PlaybackOptions options;
    options.render = small();
    options.first = 0;
    options.last = 4;
    // A rate no frame can meet: the pre-roll's frame sets the regulator on its last step.
    options.fps = 1e6;
    std::vector<PlaybackQuality> steps;
    int frames = 0;
    const PlaybackSummary summary = playScene(
        scene, options, [&](const FrameStats& s, const Image& image, const PlaybackQuality& q) {
            EXPECT_EQ(s.index, options.first + frames);
            EXPECT_DOUBLE_EQ(s.budget.seconds, 1e-6);
            EXPECT_EQ(image.width, 96);
            steps.push_back(q);
            ++frames;
            return true;
        });
    EXPECT_EQ(summary.frames, 4);
    EXPECT_EQ(summary.deadlinesMet, 0);
    EXPECT_GT(summary.prerollSeconds, 0.0);
    ASSERT_EQ(steps.size(), 4u);
    for (const PlaybackQuality& q : steps) {
        // The scene shades per sample at 4 samples: seven steps, the last at one sample.
        EXPECT_EQ(q.level, 6);
        EXPECT_EQ(q.step.rate, ShadingRate::Quad);
        EXPECT_EQ(q.step.footprintScale, 2.0f);
        EXPECT_EQ(q.step.samplesPerPixel, 1);
    }
    // The ladder as measured in the pre-roll, and where the frames were played.
    ASSERT_EQ(summary.steps.size(), 7u);
    EXPECT_EQ(summary.steps[0].step.rate, ShadingRate::Sample);
    EXPECT_EQ(summary.steps[6].step.samplesPerPixel, 1);
    for (const PlaybackStep& p : summary.steps) EXPECT_GT(p.dynamicSeconds, 0.0);
    // Each measured with the tiles its footprints read filled, none falling back.
    for (const PlaybackStep& p : summary.steps) EXPECT_EQ(p.probeFallbacks, 0u);
    EXPECT_EQ(summary.steps[6].frames, 4);
    for (size_t k = 0; k < 6; ++k) EXPECT_EQ(summary.steps[k].frames, 0);
}

}  // namespace
}  // namespace mpshade

namespace mpshade {
namespace {

// A camera panning from one ball to another that is out of view at first.
std::string writePanScene() {
    const std::string path = test::testFolder("mpshade_playback") + "pan_scene.json";
    std::ofstream f(path);
    f << R"({
  "settings": {"width": 64, "height": 48, "fps": 10, "duration": 2.0, "samples_per_pixel": 1},
  "camera": {"fov_y": 30, "near": 0.1, "far": 100, "keys": [
    {"t": 0, "eye": [0, 0, 6], "target": [0, 0, 0]},
    {"t": 2, "eye": [0, 0, 6], "target": [8, 0, 0]}]},
  "lights": [{"type": "distant", "direction": [0, -1, -1], "color": [1, 1, 1]}],
  "shaders": {"marble": ")"
      << test::sourcePath("examples/shaders/marble.sl") << R"("},
  "objects": [
    {"name": "here", "geometry": {"type": "sphere", "radius": 1.0}, "shader": "marble"},
    {"name": "ahead", "geometry": {"type": "sphere", "radius": 1.0}, "shader": "marble",
     "transform": {"translate": [8, 0, 0]}}]
})";
    return path;
}

int firstSeenFrame(const std::vector<FrameStats>& frames, uint32_t object) {
    for (const FrameStats& s : frames)
        for (const StaticRunDue& d : s.staticWork.due)
            if (d.object == object && d.cause == StaticRunDue::FirstSeen) return s.index;
    return -1;
}

TEST(Playback, AnObjectEnteringTheViewIsBuiltBeforeItsFirstFrame) {
    const Scene scene = loadScene(writePanScene());
    ASSERT_EQ(scene.objects[1].name, "ahead");
    PlaybackOptions options;
    options.render.width = 64;
    options.render.height = 48;
    options.first = 0;
    options.last = 20;
    options.fps = 2.0;  // half a second a frame: slack for building ahead
    std::vector<FrameStats> without, with;
    options.lookAheadSeconds = 0.0;
    playScene(scene, options, [&](const FrameStats& s, const Image&, const PlaybackQuality&) {
        without.push_back(s);
        return true;
    });
    // Without looking ahead, the ball ahead is first seen (and built) some frames in.
    const int enters = firstSeenFrame(without, 1);
    ASSERT_GT(enters, 1);
    options.lookAheadSeconds = 1.0;
    playScene(scene, options, [&](const FrameStats& s, const Image&, const PlaybackQuality&) {
        with.push_back(s);
        return true;
    });
    EXPECT_EQ(firstSeenFrame(with, 1), -1);  // never due: it was ready
    int builtBefore = 0;
    for (const FrameStats& s : with)
        if (s.index < enters) builtBefore += s.budget.builtAhead;
    EXPECT_EQ(builtBefore, 1);
    // At its first frame nothing was built, and it was drawn: the frame shaded as many
    // points as the one that built it then (its representative view differs a little, so
    // its silhouette may cover a few samples more or less).
    const size_t k = static_cast<size_t>(enters - options.first);
    EXPECT_EQ(with[k].staticWork.work.runs, 0);
    EXPECT_GT(without[k].staticWork.work.runs, 0);
    EXPECT_NEAR(static_cast<double>(with[k].shadedPoints),
                static_cast<double>(without[k].shadedPoints), 0.05 * without[k].shadedPoints);
}

TEST(Playback, AnObjectEnteringTheViewHasItsTilesBeforeItsFrames) {
    // Large enough that the ball reads finer levels than the always-resident ones: a
    // prediction of the frame ahead, in the slack, fills what the next frames read;
    // without prefetching it is missing.
    const Scene scene = loadScene(writePanScene());
    PlaybackOptions options;
    options.render.width = 256;
    options.render.height = 192;
    options.first = 0;
    options.last = 20;
    options.fps = 1.0;  // a second a frame: slack even under the sanitizers
    options.lookAheadSeconds = 1.0;
    auto play = [&](bool prefetch) {
        options.prefetch = prefetch;
        std::vector<FrameStats> frames;
        playScene(scene, options, [&](const FrameStats& s, const Image&, const PlaybackQuality&) {
            frames.push_back(s);
            return true;
        });
        return frames;
    };
    const std::vector<FrameStats> with = play(true), without = play(false);
    ASSERT_EQ(with.size(), without.size());
    size_t k = 0;  // the first frame that draws both balls
    while (k < with.size() && with[k].objectsDrawn < 2) ++k;
    ASSERT_LT(k, with.size());
    ASSERT_GT(k, 0u);
    ASSERT_EQ(without[k].objectsDrawn, 2u);
    // Over the frames that see it (its first shows a sliver: the always-resident levels
    // serve it), measured 19 missing tiles with prefetching against 87 without.
    uint64_t missingWith = 0, missingWithout = 0;
    for (size_t f = k; f < with.size(); ++f) {
        missingWith += with[f].tiles.missing;
        missingWithout += without[f].tiles.missing;
    }
    RecordProperty("missing", std::to_string(missingWith) + " with, " +
                                  std::to_string(missingWithout) + " without prefetching");
    EXPECT_GT(missingWithout, 20u);
    EXPECT_LT(missingWith * 2, missingWithout);
}

}  // namespace
}  // namespace mpshade

namespace mpshade {
namespace {

TEST(Playback, TheBackgroundFillerEvictsUnderTheFramesProbesWithinTheCache) {
    // The filler beside the dynamic phase, with no time for fills in any frame and a cache
    // a few frames overflow: it fills and evicts while the frames' probes read the same
    // maps. Every frame is drawn, finite, with the tiles within the cache (beyond the
    // always-resident levels); run under the sanitizers in CI. Between frames the test
    // waits for the worker to settle (at normal priority, so other processes on the
    // machine cannot starve it), so what it does per frame does not depend on the load.
    // Float maps: the budget below is set by their tiles' bytes.
    Scene scene = loadScene(test::sourcePath("examples/vase/scene.json"));
    for (SceneObject& object : scene.objects) object.shadermapPrecision = MapPrecision::Float;
    MultiphaseOptions o = budgeted(1e-6, 0.0);
    o.backgroundFills = true;
    o.backgroundDuringFrames = true;
    o.backgroundIdlePriority = false;
    o.backgroundQueue = 48;
    o.mapMemoryBytes = size_t{5} << 20;  // the always-resident levels take 3.5 MB
    MultiphaseRenderer play(scene, o);
    RenderOptions r;
    r.width = 240;
    r.height = 135;
    uint64_t filled = 0, evicted = 0;
    for (int frame = 0; frame < 16; ++frame) {
        FrameStats s;
        const Image image = play.renderFrame(frame, r, s);
        filled += s.background.tilesFilled;
        evicted += s.background.tilesEvicted;
        EXPECT_LE(s.tiles.residentBytes - s.tiles.residentPinnedBytes, o.mapMemoryBytes) << frame;
        for (float v : image.rgba) ASSERT_TRUE(std::isfinite(v)) << frame;
        EXPECT_GT(coverage(image), 0.3);
        for (int wait = 0; wait < 6000 && !play.backgroundSettled(); ++wait)
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        ASSERT_TRUE(play.backgroundSettled()) << frame;
    }
    EXPECT_GT(filled, 0u);
    EXPECT_GT(evicted, 0u);
}

TEST(Playback, AOneMegabyteCacheHoldsEveryFrameAndStillDrawsThem) {
    // The maps could use far more (the vase's frames fill 16 MB at its own size): with a
    // 1 MB cache, no frame holds more than 1 MB of tiles beyond the always-resident levels,
    // and every frame is drawn, from coarser levels.
    const Scene scene = loadScene(test::sourcePath("examples/vase/scene.json"));
    PlaybackOptions options;
    options.render.width = 240;
    options.render.height = 135;
    options.first = 0;
    options.last = 12;
    options.fps = 4.0;  // time enough: memory is what holds the fills back
    options.cacheBytes = size_t{1} << 20;
    int frames = 0;
    uint64_t deferred = 0;
    playScene(scene, options, [&](const FrameStats& s, const Image& image, const PlaybackQuality&) {
        ++frames;
        EXPECT_LE(s.tiles.residentBytes - s.tiles.residentPinnedBytes, options.cacheBytes)
            << s.index;
        EXPECT_LE(s.tiles.residentPinnedBytes, s.tiles.residentBytes);
        deferred += s.budget.tilesDeferred;
        double covered = 0.0;
        size_t nonFinite = 0;
        for (size_t p = 3; p < image.rgba.size(); p += 4) {
            nonFinite += std::isfinite(image.rgba[p - 1]) ? 0 : 1;
            covered += image.rgba[p];
        }
        EXPECT_EQ(nonFinite, 0u);
        EXPECT_GT(covered, 0.3 * image.width * image.height);
        return true;
    });
    EXPECT_EQ(frames, 12);
    EXPECT_GT(deferred, 0u);  // the cache, not time, left tiles unfilled
}

TEST(Playback, AFrameAtFewerSamplesRefinesItsRateAtThem) {
    // The ladder of a per-sample scene at 4 spp: 0 per sample, 1 per pixel, 2 per pixel x2,
    // 3 per 2x2, 4 per 2x2 x2, 5 the same at 2 spp, 6 at 1 spp. A frame at 5 or 6 refines to
    // per 2x2, per pixel and per sample at its own samples (it had refined to nothing: no step
    // above it had its samples); one at 4 the same; per pixel x2 to per pixel, then per
    // sample; the best step to nothing.
    const QualityRegulator regulator(ShadingRate::Sample, 4);
    ASSERT_EQ(regulator.levels(), 7);
    const std::vector<RefineStep> fromQuad = {
        {ShadingRate::Quad, 1.0f}, {ShadingRate::Pixel, 1.0f}, {ShadingRate::Sample, 1.0f}};
    for (int level : {4, 5, 6}) {
        SCOPED_TRACE(level);
        EXPECT_EQ(refineStepsAbove(regulator, level), fromQuad);
    }
    const std::vector<RefineStep> fromPixel = {{ShadingRate::Pixel, 1.0f},
                                               {ShadingRate::Sample, 1.0f}};
    EXPECT_EQ(refineStepsAbove(regulator, 2), fromPixel);
    EXPECT_EQ(refineStepsAbove(regulator, 1),
              (std::vector<RefineStep>{{ShadingRate::Sample, 1.0f}}));
    EXPECT_TRUE(refineStepsAbove(regulator, 0).empty());
}

TEST(Playback, RefiningTheStepGoesDownLaterThanTheWholeFrameLadder) {
    // Frames whose dynamic phase takes 0.78 of the budget (0.5 + 0.28, exact in binary
    // sums): two in a row step the whole-frame ladder down (above 0.7), not a refined one
    // (at most 0.8); 0.8125 steps both down.
    auto frame = [](double shade) {
        FrameStats s;
        s.dynamic.rasterSeconds = 0.5;
        s.dynamic.shadeSeconds = shade;
        return s;
    };
    PlaybackOptions refined;
    PlaybackOptions whole;
    whole.refine.enabled = false;
    ASSERT_TRUE(refined.refine.enabled);
    EXPECT_EQ(playbackRegulatorOptions(refined).slowDownAt, refined.refine.slowDownAt);
    EXPECT_EQ(playbackRegulatorOptions(whole).slowDownAt, whole.regulator.slowDownAt);
    for (const double shade : {0.28, 0.3125}) {
        QualityRegulator r(ShadingRate::Sample, 4, playbackRegulatorOptions(refined));
        QualityRegulator w(ShadingRate::Sample, 4, playbackRegulatorOptions(whole));
        for (int k = 0; k < 2; ++k) {
            r.update(frame(shade), 1.0);
            w.update(frame(shade), 1.0);
        }
        EXPECT_EQ(w.level(), 1) << shade;
        EXPECT_EQ(r.level(), shade > 0.3 ? 1 : 0) << shade;
    }
}

}  // namespace
}  // namespace mpshade
