// TileRefiner (tile_refiner.h): tiles refined in order of the error their cheap shading
// shows (a striped corner of a flat plane first), none starved when age alone decides,
// nothing refined once the deadline has passed, every tile refined given the time (the
// image then that of the best step), and the error it measured and estimated.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../phases/dynamic_frame.h"
#include "controller/multiphase_renderer.h"
#include "controller/tile_refiner.h"
#include "phases/image_compare.h"
#include "test_support.h"

namespace mpshade {
namespace {

using test::Frame;
using test::shadeWhole;

constexpr int kW = 64, kH = 36;

// A grey plane filling the view from above, striped finely (much finer than a pixel at 2x2
// shading) where the object-space x is above 1.3 (one side of the image), elsewhere a
// gentle ramp (each tile's per-sample shading differs a little from its 2x2 shading).
// A folder of the test's own: ctest runs the tests of this file in parallel processes, and
// one rewriting a file another was reading had failed it now and then.
std::string writeStripedPlane() {
    const std::string dir = ::testing::TempDir() + "mpshade_refiner_" +
                            ::testing::UnitTest::GetInstance()->current_test_info()->name() + "/";
    std::filesystem::create_directories(dir);
    std::ofstream(dir + "striped.sl")
        << "surface striped() { float on = step(1.3, P[0]);"
           " Ci = color(0.5 + 0.45 * on * sin(P[0] * 90.0) + 0.01 * P[2]); }";
    std::ofstream(dir + "scene.json") << R"({ "settings": { "width": 64, "height": 36,
      "samples_per_pixel": 4, "fps": 1, "duration": 1, "background": [0, 0, 0] },
      "camera": { "fov_y": 40, "near": 0.05, "far": 100,
                  "keys": [ { "t": 0, "eye": [0, 4, 0.01], "target": [0, 0, 0] } ] },
      "shaders": { "striped": "striped.sl" },
      "objects": [ { "name": "plane", "geometry": { "type": "plane", "size": [20, 20] },
                     "shader": "striped" } ] })";
    return dir + "scene.json";
}

// A frame of `f` shaded per 2x2 pixels and resolved.
struct Cheap {
    DynamicPhase phase;
    Image image;
    explicit Cheap(Frame& f) : phase(f.scene) {
        shadeWhole(f, phase, f.state, f.options(ShadingRate::Quad));
        phase.resolve(image);
    }
};

const RefineStep kQuad{ShadingRate::Quad, 1.0f};
const std::vector<RefineStep> kBetter = {{ShadingRate::Pixel, 1.0f}, {ShadingRate::Sample, 1.0f}};
const auto kNever = std::chrono::steady_clock::time_point::max();

// The columns where the stripes are: those whose pixels vary along the row.
bool striped(const Image& image, int x) {
    double spread = 0.0;
    for (int y = 0; y < image.height; ++y) {
        const float a = image.rgba[4 * (static_cast<size_t>(y) * image.width + x)];
        spread = std::max(spread, std::fabs(static_cast<double>(a) - 0.5));
    }
    return spread > 0.05;
}

TEST(TileRefiner, TheTileWithTheMostErrorGoesFirst) {
    Frame f(writeStripedPlane(), Representation::Facets, kW, kH);
    Cheap cheap(f);
    const Image before = cheap.image;
    RefineOptions o;
    o.maxTiles = 1;
    TileRefiner refiner(o);
    RefineStats stats;
    std::vector<TileRequest> missing;
    refiner.refine(cheap.phase, kQuad, kBetter, kNever, cheap.image, stats, missing);
    ASSERT_TRUE(stats.ran);
    EXPECT_EQ(stats.tileSize, 16);
    EXPECT_EQ(stats.tiles, 12);  // 4 x 3 tiles, the last row 4 pixels tall
    EXPECT_EQ(stats.steps, 3);
    EXPECT_EQ(stats.refined[2], 1);  // one tile, both passes
    EXPECT_EQ(stats.refined[1], 0);
    EXPECT_EQ(stats.pixelsAt[2], 256u);
    EXPECT_EQ(stats.pixelsAt[0] + stats.pixelsAt[1] + stats.pixelsAt[2], uint64_t{kW} * kH);
    EXPECT_GT(stats.threshold, 0.0);
    // The pixels that changed are those of (and the filter's pixel around) one tile, in the
    // stripes.
    int changedX0 = kW, changedX1 = -1;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x)
            for (int k = 0; k < 3; ++k) {
                const size_t i = 4 * (static_cast<size_t>(y) * kW + x) + k;
                if (cheap.image.rgba[i] != before.rgba[i])
                    changedX0 = std::min(changedX0, x), changedX1 = std::max(changedX1, x);
            }
    ASSERT_GE(changedX1, changedX0);
    EXPECT_LE(changedX1 - changedX0, 17);
    const int centre = (changedX0 + changedX1) / 2;
    EXPECT_TRUE(striped(before, centre)) << centre;
    // The squared change it reports is the one made, over the tile's pixels.
    double sum = 0.0;
    for (size_t i = 0; i < before.rgba.size(); i += 4)
        for (int k = 0; k < 3; ++k) {
            const double d = std::clamp(cheap.image.rgba[i + k], 0.0f, 1.0f) -
                             std::clamp(before.rgba[i + k], 0.0f, 1.0f);
            sum += d * d;
        }
    // Changes beyond the tile (the filter's reach) are not the tile's: at most that much.
    EXPECT_GT(stats.gainMse, 0.0);
    EXPECT_LE(stats.gainMse * 3.0 * 256.0, sum * (1.0 + 1e-9));
    EXPECT_GE(stats.gainMse * 3.0 * 256.0, 0.5 * sum);
}

TEST(TileRefiner, AgeAloneVisitsEveryTileOnceBeforeAnyTwice) {
    Frame f(writeStripedPlane(), Representation::Facets, kW, kH);
    RefineOptions o;
    o.maxTiles = 1;
    o.errorWeight = 0.0;
    o.ageWeight = 1.0;
    o.hysteresis = 0.0;
    TileRefiner refiner(o);
    std::set<std::pair<int, int>> visited;
    const std::vector<RefineStep> best = {{ShadingRate::Sample, 1.0f}};
    for (int frame = 0; frame < 12; ++frame) {
        Cheap cheap(f);  // each frame shaded afresh
        const Image before = cheap.image;
        RefineStats stats;
        std::vector<TileRequest> missing;
        refiner.refine(cheap.phase, kQuad, best, kNever, cheap.image, stats, missing);
        ASSERT_EQ(stats.refined[1], 1);
        // Which tile: the pixels that changed, the filter's one pixel around it included.
        int x0 = kW, y0 = kH, x1 = -1, y1 = -1;
        for (int y = 0; y < kH; ++y)
            for (int x = 0; x < kW; ++x)
                if (cheap.image.rgba[4 * (static_cast<size_t>(y) * kW + x)] !=
                    before.rgba[4 * (static_cast<size_t>(y) * kW + x)])
                    x0 = std::min(x0, x), y0 = std::min(y0, y), x1 = std::max(x1, x),
                    y1 = std::max(y1, y);
        ASSERT_GE(x1, x0) << "frame " << frame << ": nothing changed";
        const int tx = (x0 + x1) / 2 / 16, ty = (y0 + y1) / 2 / 16;
        EXPECT_TRUE(visited.insert({tx, ty}).second) << "tile " << tx << "," << ty << " twice";
    }
    EXPECT_EQ(visited.size(), 12u);
}

TEST(TileRefiner, ATileWhoseColourChangedSinceTheLastFrameGoesFirst) {
    // Watson's temporal error: the last frame's means kept, a flat tile away from the
    // stripes brightened by 0.3 in this frame's cheap image outranks the striped tiles
    // when the temporal term weighs enough (planting "means never kept" fails it).
    Frame f(writeStripedPlane(), Representation::Facets, kW, kH);
    RefineOptions o;
    o.maxTiles = 1;
    o.errorWeight = 1.0;
    o.ageWeight = 0.0;
    o.hysteresis = 0.0;
    o.temporalWeight = 1000.0;
    TileRefiner refiner(o);
    const std::vector<RefineStep> best = {{ShadingRate::Sample, 1.0f}};
    RefineStats stats;
    std::vector<TileRequest> missing;
    Cheap first(f);
    refiner.refine(first.phase, kQuad, best, kNever, first.image, stats, missing);
    Cheap second(f);
    // The flat tile: a column of tiles without stripes, in the middle row.
    int column = -1;
    for (int tx = 0; tx < kW / 16 && column < 0; ++tx)
        if (!striped(second.image, tx * 16) && !striped(second.image, tx * 16 + 15)) column = tx;
    ASSERT_GE(column, 0);
    const PixelRect flat{16 * column, 16, 16 * column + 16, 32};
    for (int y = flat.y0; y < flat.y1; ++y)
        for (int x = flat.x0; x < flat.x1; ++x)
            for (int k = 0; k < 3; ++k)
                second.image.rgba[4 * (static_cast<size_t>(y) * kW + x) + k] += 0.3f;
    const Image before = second.image;
    refiner.refine(second.phase, kQuad, best, kNever, second.image, stats, missing);
    ASSERT_EQ(stats.refined[1], 1);
    // The refined tile's pixels lose the 0.3 (its samples are resolved anew); beyond the
    // filter's pixel around it nothing changes by as much.
    double inside = 0.0, outside = 0.0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            const size_t i = 4 * (static_cast<size_t>(y) * kW + x);
            const double d = std::fabs(second.image.rgba[i] - before.rgba[i]);
            const bool in = x > flat.x0 && x + 1 < flat.x1 && y > flat.y0 && y + 1 < flat.y1;
            const bool near = x + 1 >= flat.x0 && x <= flat.x1 && y + 1 >= flat.y0 && y <= flat.y1;
            if (in) inside = std::max(inside, d);
            if (!near) outside = std::max(outside, d);
        }
    EXPECT_GT(inside, 0.25);
    EXPECT_LT(outside, 0.25);
}

TEST(TileRefiner, APassedDeadlineRefinesNothingAndAmpleTimeReachesTheBestStep) {
    Frame f(writeStripedPlane(), Representation::Facets, kW, kH);
    Cheap cheap(f);
    const Image before = cheap.image;
    TileRefiner refiner;
    RefineStats stats;
    std::vector<TileRequest> missing;
    refiner.refine(cheap.phase, kQuad, kBetter, std::chrono::steady_clock::now(), cheap.image,
                   stats, missing);
    EXPECT_TRUE(stats.ran);
    EXPECT_EQ(stats.refined[1] + stats.refined[2], 0);
    EXPECT_EQ(stats.pixelsAt[0], uint64_t{kW} * kH);
    EXPECT_EQ(stats.estimatedPsnr, -1.0);  // nothing measured
    EXPECT_EQ(cheap.image.rgba, before.rgba);
    // Every tile to per sample: the image of the frame shaded per sample.
    refiner.refine(cheap.phase, kQuad, kBetter, kNever, cheap.image, stats, missing);
    EXPECT_EQ(stats.refined[2], 12);
    EXPECT_EQ(stats.pixelsAt[2], uint64_t{kW} * kH);
    EXPECT_EQ(stats.threshold, 0.0);
    EXPECT_EQ(stats.estimatedPsnr, 99.0);  // nothing left
    DynamicPhase direct(f.scene);
    shadeWhole(f, direct, f.state, f.options(ShadingRate::Sample));
    Image want;
    direct.resolve(want);
    for (size_t k = 0; k < want.rgba.size(); ++k)
        ASSERT_NEAR(cheap.image.rgba[k], want.rgba[k], 1e-6f) << k;
    // Nothing better to go to: no refinement at all.
    refiner.refine(cheap.phase, kQuad, {}, kNever, cheap.image, stats, missing);
    EXPECT_FALSE(stats.ran);
}

TEST(TileRefiner, TheImageRefinedInPlacesIsTheWholeResolveOfItsSamples) {
    // Three tiles refined to per pixel and per sample, the rest per 2x2 pixels: only the
    // pixels near the three are resolved again, and the image is, bit for bit, what
    // resolving all the frame's samples gives (resolving only the tiles themselves, or
    // without their filter's ring, would not be).
    Frame f(writeStripedPlane(), Representation::Facets, kW, kH);
    RefineOptions o;
    o.maxTiles = 3;
    TileRefiner refiner(o);
    Cheap cheap(f);
    const Image before = cheap.image;
    RefineStats stats;
    std::vector<TileRequest> missing;
    refiner.refine(cheap.phase, kQuad, kBetter, kNever, cheap.image, stats, missing);
    ASSERT_EQ(stats.refined[1] + stats.refined[2], 3);
    EXPECT_GT(stats.gainMse, 0.0);
    EXPECT_NE(cheap.image.rgba, before.rgba);
    Image whole;
    cheap.phase.resolveAgain(whole);
    ASSERT_EQ(whole.rgba.size(), cheap.image.rgba.size());
    EXPECT_EQ(
        std::memcmp(whole.rgba.data(), cheap.image.rgba.data(), whole.rgba.size() * sizeof(float)),
        0);
}

TEST(TileRefiner, TheEstimateFollowsTheErrorLeft) {
    // Half the tiles refined: the estimated PSNR lies below the 99 of nothing left and, the
    // stripes being most of the error, within a few dB of the measured one.
    Frame f(writeStripedPlane(), Representation::Facets, kW, kH);
    DynamicPhase direct(f.scene);
    shadeWhole(f, direct, f.state, f.options(ShadingRate::Sample));
    Image truth;
    direct.resolve(truth);
    Cheap cheap(f);
    RefineOptions o;
    o.maxTiles = 2;
    TileRefiner refiner(o);
    RefineStats stats;
    std::vector<TileRequest> missing;
    const std::vector<RefineStep> best = {{ShadingRate::Sample, 1.0f}};
    refiner.refine(cheap.phase, kQuad, best, kNever, cheap.image, stats, missing);
    const double measured = compareImages(cheap.image, truth).psnr;
    EXPECT_GT(stats.estimatedPsnr, 0.0);
    EXPECT_LT(stats.estimatedPsnr, 99.0);
    EXPECT_NEAR(stats.estimatedPsnr, measured, 6.0) << measured;
}

}  // namespace
}  // namespace mpshade

namespace mpshade {
namespace {

TEST(TileRefiner, ARendererWithABudgetRefinesEveryTileItHasTimeFor) {
    // The vase with a budget nothing exhausts: a frame per pixel refined per sample ends as
    // the frame rendered per sample at constant quality (within the Feline setup's sharing,
    // probe_batch.h), and the tiles its finer footprints missed are filled after it.
    const Scene scene = loadScene(test::sourcePath("examples/vase/scene.json"));
    MultiphaseOptions o;
    o.frameBudgetSeconds = 1e6;
    o.refine.enabled = true;
    o.refine.until = 1.0;
    o.singlePhaseFrames = false;
    MultiphaseRenderer played(scene, o);
    played.setRefineSteps({{ShadingRate::Sample, 1.0f}});
    RenderOptions pixel;
    pixel.width = 64, pixel.height = 36;
    pixel.shadingRate = ShadingRate::Pixel;
    FrameStats stats;
    Image image;
    for (int pass = 0; pass < 3; ++pass) played.renderFrame(0, pixel, stats, image);
    ASSERT_TRUE(stats.refine.ran);
    EXPECT_EQ(stats.refine.steps, 2);
    EXPECT_EQ(stats.refine.pixelsAt[1], uint64_t{64} * 36 - stats.refine.pixelsAt[0]);
    EXPECT_GT(stats.refine.refined[1], 0);
    EXPECT_EQ(stats.refine.threshold, 0.0);  // every tile seeing the vase
    EXPECT_GT(stats.refine.shadingPoints, stats.shadedPoints);
    MultiphaseOptions constant;
    constant.singlePhaseFrames = false;
    // A renderer with a budget measures no footprints (playback measures them before it
    // sets one): uniform ones here too.
    constant.footprints.enabled = false;
    MultiphaseRenderer reference(scene, constant);
    RenderOptions sample = pixel;
    sample.shadingRate = ShadingRate::Sample;
    Image want;
    reference.renderFrame(0, sample, stats, want);
    EXPECT_GT(compareImages(image, want).psnr, 60.0);
    // Without steps to go to, the frame stays per pixel.
    played.setRefineSteps({});
    played.renderFrame(0, pixel, stats, image);
    EXPECT_FALSE(stats.refine.ran);
    EXPECT_LT(compareImages(image, want).psnr, 55.0);
}

}  // namespace
}  // namespace mpshade
