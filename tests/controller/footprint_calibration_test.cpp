// Footprints by object (controller/footprint_calibration.h): the measures against numbers
// worked by hand, the choice's boundary, and a render that widens a smooth object's
// footprint and keeps a finely textured one's.
#include "controller/footprint_calibration.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "controller/multiphase_renderer.h"
#include "scene/scene.h"

namespace mpshade {
namespace {

// A visibility buffer of w x h pixels, 4 samples each, one layer, every sample seeing
// `object` (count 1), or nothing where object < 0.
VisibilityBuffer visibilityOf(int w, int h, const std::vector<int>& sampleObjects) {
    VisibilityBuffer vis;
    vis.resize(w, h, 4, 1);
    for (size_t s = 0; s < sampleObjects.size(); ++s) {
        vis.count[s] = sampleObjects[s] < 0 ? 0 : 1;
        vis.object[s] = sampleObjects[s] < 0 ? 0 : static_cast<uint32_t>(sampleObjects[s]);
    }
    return vis;
}

TEST(FootprintCalibration, APixelBelongsToTheObjectEverySampleSees) {
    // Pixels: all object 1; three of 1 and one of 0; all 0; one sample seeing nothing.
    const VisibilityBuffer vis =
        visibilityOf(4, 1, {1, 1, 1, 1, 1, 1, 0, 1, 0, 0, 0, 0, 2, 2, -1, 2});
    std::vector<uint64_t> pixels;
    const std::vector<int32_t> owners = pixelOwners(vis, 3, 0, pixels);
    EXPECT_EQ(owners, (std::vector<int32_t>{1, -1, 0, -1}));
    EXPECT_EQ(pixels, (std::vector<uint64_t>{1, 1, 0}));
}

TEST(FootprintCalibration, APixelWithinTheFiltersReachOfAnotherObjectIsNotMeasured) {
    // 6 x 2 pixels, every sample of a pixel alike: object 1 in columns 0-2, nothing in
    // column 3, object 2 in columns 4-5. Margin 1: column 2 is next to nothing (kept),
    // column 4 next to nothing too; margin 2 reaches across the gap.
    std::vector<int> samples;
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 6; ++x)
            for (int k = 0; k < 4; ++k) samples.push_back(x < 3 ? 1 : x == 3 ? -1 : 2);
    const VisibilityBuffer vis = visibilityOf(6, 2, samples);
    std::vector<uint64_t> pixels;
    EXPECT_EQ(pixelOwners(vis, 3, 1, pixels),
              (std::vector<int32_t>{1, 1, 1, -1, 2, 2, 1, 1, 1, -1, 2, 2}));
    EXPECT_EQ(pixels, (std::vector<uint64_t>{0, 6, 4}));
    EXPECT_EQ(pixelOwners(vis, 3, 2, pixels),
              (std::vector<int32_t>{1, 1, -1, -1, -1, 2, 1, 1, -1, -1, -1, 2}));
    EXPECT_EQ(pixels, (std::vector<uint64_t>{0, 4, 2}));

    // A surface of object 2 behind a sample of pixel (0, 0), in a second layer: that pixel
    // and, at margin 1, its neighbours within reach are no longer object 1's alone.
    VisibilityBuffer layered;
    layered.resize(4, 1, 4, 2);
    for (size_t s = 0; s < 16; ++s) {
        layered.count[s] = 1;
        layered.object[2 * s] = 1;
    }
    layered.count[1] = 2;
    layered.object[2 * 1 + 1] = 2;
    EXPECT_EQ(pixelOwners(layered, 3, 0, pixels), (std::vector<int32_t>{-1, 1, 1, 1}));
    EXPECT_EQ(pixelOwners(layered, 3, 1, pixels), (std::vector<int32_t>{-1, -1, 1, 1}));
}

TEST(FootprintCalibration, NoiseIsTheSpreadOfTheCheckerboardsHalves) {
    // Four samples of one pixel, strata (0,0) (1,0) (0,1) (1,1): the halves are samples
    // {0, 3} and {1, 2}. Red 0.1 0.3 0.5 0.9: means 0.5 and 0.4, so the mean of the four
    // has variance (0.1)^2 (1/4) / (1/2 + 1/2) = 0.0025. Green is 2.0 everywhere but sample 0
    // (0.0): clamped to 1, the halves' means are 0.5 and 1, giving 0.0625. Blue is flat.
    SampleBuffer samples;
    samples.width = 2, samples.height = 1, samples.spp = 4;
    samples.rgba = {
        0.1f, 0.0f, 0.2f, 1, 0.3f, 2.0f, 0.2f, 1, 0.5f, 2.0f, 0.2f, 1, 0.9f, 2.0f, 0.2f, 1,
        // The second pixel is marked uniform: only its first sample was written.
        0.0f, 0.0f, 0.0f, 1, 9.0f, 9.0f, 9.0f, 1, 9.0f, 9.0f, 9.0f, 1, 9.0f, 9.0f, 9.0f, 1};
    const std::vector<uint8_t> uniform = {0, 1};
    const std::vector<int32_t> owners = {0, 0};
    std::vector<FootprintMeasure> m(1);
    addSampleNoise(samples, uniform, owners, m);
    EXPECT_NEAR(m[0].noise, (0.0025 + 0.0625 + 0.0) / 3.0, 1e-9);
    // Unowned pixels add nothing.
    std::vector<FootprintMeasure> none(1);
    addSampleNoise(samples, {}, std::vector<int32_t>{-1, -1}, none);
    EXPECT_EQ(none[0].noise, 0.0);
}

TEST(FootprintCalibration, ChangeIsTheClampedSquaredDifferenceOverTheObjectsPixels) {
    Image a(3, 1), b(3, 1);
    // Pixel 0 (object 0): red 0.2 against 0.5; pixel 1 (object 1): 3.0 against 0.9, clamped
    // 1 against 0.9; pixel 2 unowned.
    a.pixel(0, 0)[0] = 0.2f, b.pixel(0, 0)[0] = 0.5f;
    a.pixel(1, 0)[0] = 3.0f, b.pixel(1, 0)[0] = 0.9f;
    a.pixel(2, 0)[1] = 1.0f;
    const std::vector<int32_t> owners = {0, 1, -1};
    std::vector<FootprintMeasure> m(2);
    const std::vector<size_t> both = {0, 1};
    const std::vector<float> scales = {1.5f, 1.25f};
    addChange(a, b, owners, both, scales, m);
    ASSERT_EQ(m[0].change.size(), 1u);
    EXPECT_NEAR(m[0].change[0], 0.09 / 3.0, 1e-7);
    EXPECT_NEAR(m[1].change[0], 0.01 / 3.0, 1e-7);
    EXPECT_EQ(m[0].scales, (std::vector<float>{1.5f}));
    EXPECT_EQ(m[1].scales, (std::vector<float>{1.25f}));
    // Only the objects named get an entry.
    const std::vector<size_t> second = {1};
    addChange(a, b, owners, second, scales, m);
    EXPECT_EQ(m[0].change.size(), 1u);
    EXPECT_EQ(m[1].change.size(), 2u);
    EXPECT_EQ(m[1].scales.size(), 2u);
}

TEST(FootprintCalibration, TheLargestScaleAllowedBelowEveryScaleRefused) {
    FootprintCalibrationOptions o;
    o.tolerance = 0.1;
    o.floor = 1e-6;
    FootprintMeasure m;
    m.pixels = 1000;
    m.noise = 2.0;
    const double limit = 0.1 * 2.0 + 1e-6 * 1000;  // 0.201
    // Tried in bisection order: 1.41 allowed (exactly at the limit), 1.78 refused, 1.59
    // allowed.
    m.scales = {1.41f, 1.78f, 1.59f};
    m.change = {limit, limit * 1.0001, 0.05};
    EXPECT_TRUE(changeAllowed(m, 0, o));
    EXPECT_FALSE(changeAllowed(m, 1, o));
    EXPECT_EQ(chosenFootprint(m, o), 1.59f);
    // An allowed scale above one refused does not count.
    m.scales = {1.41f, 1.12f, 2.0f};
    m.change = {0.3, 0.1, 0.1};
    EXPECT_EQ(chosenFootprint(m, o), 1.12f);
    m.scales = {1.41f, 1.12f};
    m.change = {0.3, 0.3};
    EXPECT_EQ(chosenFootprint(m, o), 1.0f);
    // A scale whose change was not measured is not taken.
    m.scales = {1.41f, 1.78f};
    m.change = {0.05};
    EXPECT_EQ(chosenFootprint(m, o), 1.41f);
    // Without noise the floor alone: 1e-6 a pixel.
    m.noise = 0.0;
    m.scales = {1.12f, 1.26f};
    m.change = {0.0009, 0.0011};
    EXPECT_EQ(chosenFootprint(m, o), 1.12f);
}

TEST(FootprintCalibration, TheCheckerboardKeepsTheCornersTilesAwayFromTheirInnerEdges) {
    // 10 x 6 pixels, tiles of 4, margin 1: tiles (0,0) (2,0) (1,1) kept. Tile (0,0) spans
    // x 0..3, y 0..3: its image edges keep their pixels, its inner edges (x 3, y 3) lose them.
    std::vector<int32_t> owners(60, 7);
    keepCheckerboard(owners, 10, 6, 4, 1);
    auto at = [&](int x, int y) { return owners[static_cast<size_t>(y) * 10 + x]; };
    EXPECT_EQ(at(0, 0), 7);
    EXPECT_EQ(at(2, 2), 7);
    EXPECT_EQ(at(3, 2), -1);  // the inner edge
    EXPECT_EQ(at(2, 3), -1);
    EXPECT_EQ(at(4, 0), -1);  // tile (1, 0)
    // Tile (1, 1): x 4..7, y 4..5 (clipped by the image): x 5..6 on row 5 only.
    EXPECT_EQ(at(5, 4), -1);
    EXPECT_EQ(at(4, 5), -1);
    EXPECT_EQ(at(5, 5), 7);  // on the image's bottom edge
    EXPECT_EQ(at(9, 0), 7);  // tile (2, 0): the image's right edge
    EXPECT_EQ(at(8, 1), -1);
    EXPECT_EQ(at(9, 3), -1);
    int kept = 0;
    for (int32_t v : owners) kept += v == 7 ? 1 : 0;
    EXPECT_EQ(kept, 9 + 2 + 3);  // tiles (0,0), (1,1), (2,0)
}

TEST(FootprintCalibration, TilesHoldingTheObjectsPixelsClippedToTheImage) {
    // 5 x 3 pixels in tiles of 2: object 3 at (0, 0) and (4, 2), object 1 at (2, 0).
    std::vector<int32_t> owners(15, -1);
    owners[0] = 3, owners[2 * 5 + 4] = 3, owners[2] = 1;
    const std::vector<size_t> three = {3};
    const std::vector<PixelRect> tiles = tilesOwnedBy(owners, 5, 3, three, 2);
    ASSERT_EQ(tiles.size(), 2u);
    EXPECT_EQ(tiles[0].x0, 0);
    EXPECT_EQ(tiles[0].x1, 2);
    EXPECT_EQ(tiles[0].y1, 2);
    EXPECT_EQ(tiles[1].x0, 4);
    EXPECT_EQ(tiles[1].x1, 5);
    EXPECT_EQ(tiles[1].y0, 2);
    EXPECT_EQ(tiles[1].y1, 3);
}

// Two spheres under one shader: the left one's static colour varies slowly, the right one's
// at the scale of its texels. The camera pans unless `still`.
Scene twoSpheres(bool still = false, bool approach = false) {
    const std::string dir = ::testing::TempDir() + (approach ? "mpshade_footprints_approach/"
                                                    : still  ? "mpshade_footprints_still/"
                                                             : "mpshade_footprints/");
    std::filesystem::create_directories(dir);
    std::ofstream(dir + "speckle.sl")
        << "surface speckle(float freq = 1.0) { float n = 0.5 + 0.5 * snoise(P * freq); color Cd "
           "= color(n, 0.6 * n, 0.3); Ci = Cd * (ambient() + diffuse(N)) + 0.3 * specular(N, -I, "
           "0.3); }";
    std::ofstream(dir + "scene.json") << R"({
      "settings": { "width": 96, "height": 48, "samples_per_pixel": 4, "background": [0, 0, 0],
                    "fps": 24, "duration": )" +
                                             std::string(approach ? "2" : "1") + R"( },
      "camera": { "fov_y": 30, "near": 0.1, "far": 100, "keys": [
        { "t": 0, "eye": [0, 0, )" + std::string(approach ? "40" : "6") +
                                             R"(], "target": [0, 0, 0] },
        { "t": 1, "eye": [)" + std::string(still ? "0" : "0.5") +
                                             R"(, 0, 6], "target": [0, 0, 0] })" +
                                             std::string(approach ? R"(,
        { "t": 2, "eye": [0.5, 0, 6], "target": [0, 0, 0] })"
                                                                  : "") +
                                             R"( ] },
      "lights": [ { "type": "ambient", "color": [0.2, 0.2, 0.2] },
                  { "type": "distant", "direction": [-1, -1, -1], "color": [1, 1, 1], "intensity": 2 } ],
      "shaders": { "s": "speckle.sl" },
      "objects": [
        { "name": "smooth", "geometry": { "type": "sphere", "radius": 1 }, "shader": "s",
          "params": { "freq": 0.05 }, "representation": "shadermap",
          "transform": { "translate": [-1.3, 0, 0] } },
        { "name": "fine", "geometry": { "type": "sphere", "radius": 1 }, "shader": "s",
          "params": { "freq": 90 }, "representation": "shadermap",
          "transform": { "translate": [1.3, 0, 0] } } ] })";
    return loadScene(dir + "scene.json");
}

TEST(FootprintCalibration, ASmoothObjectWidensAndAFinelyTexturedOneDoesNot) {
    const Scene scene = twoSpheres();
    MultiphaseOptions o;
    o.singlePhaseFrames = false;
    MultiphaseRenderer measured(scene, o);
    FrameStats first, second;
    const Image firstImage = measured.renderFrame(0, {}, first);
    EXPECT_EQ(first.footprintCalibration.objects, 2u);
    const ObjectReport& smooth = measured.report(0);
    const ObjectReport& fine = measured.report(1);
    ASSERT_GT(smooth.footprint.pixels, 256u);
    ASSERT_GT(fine.footprint.pixels, 256u);
    // Bisection over the six candidates: up to the largest for the smooth one, down past
    // the smallest for the fine one.
    EXPECT_EQ(smooth.footprintScale, 2.0f);
    EXPECT_EQ(smooth.footprint.scales, (std::vector<float>{1.41f, 1.78f, 2.0f}));
    EXPECT_EQ(fine.footprintScale, 1.0f);
    EXPECT_EQ(fine.footprint.scales, (std::vector<float>{1.41f, 1.12f}));
    ASSERT_EQ(fine.footprint.change.size(), 2u);
    EXPECT_GT(fine.footprint.change[1], o.footprints.tolerance * fine.footprint.noise);
    const Image image = measured.renderFrame(1, {}, second);
    EXPECT_EQ(second.footprintCalibration.objects, 0u);  // measured once

    // The frames after are those of a renderer told the same footprints outright.
    MultiphaseOptions told = o;
    told.footprints.enabled = false;
    told.dynamic.objectFootprint = {smooth.footprintScale, fine.footprintScale};
    MultiphaseRenderer given(scene, told);
    FrameStats g;
    given.renderFrame(0, {}, g);
    const Image want = given.renderFrame(1, {}, g);
    ASSERT_EQ(image.rgba.size(), want.rgba.size());
    EXPECT_EQ(image.rgba, want.rgba);
    // The measured frame is the one its own pass shaded, at uniform footprints: the trial
    // passes' samples are not left in it. The frames after are not uniform ones.
    told.dynamic.objectFootprint = {};
    MultiphaseRenderer uniform(scene, told);
    EXPECT_EQ(uniform.renderFrame(0, {}, g).rgba, firstImage.rgba);
    EXPECT_NE(uniform.renderFrame(1, {}, g).rgba, want.rgba);
}

TEST(FootprintCalibration, AnObjectTooSmallAtFirstIsMeasuredOnceItHasGrown) {
    // The camera comes in from 40 units to 6 over frames 0-24, then holds (48 frames): at
    // first each sphere is a few pixels, too few to measure (minPixels); it is looked at
    // again as it grows, and measured once it owns enough.
    const Scene scene = twoSpheres(false, true);
    MultiphaseOptions o;
    o.singlePhaseFrames = false;
    MultiphaseRenderer renderer(scene, o);
    int measuredAt = -1;
    for (int frame = 0; frame <= 24 && measuredAt < 0; ++frame) {
        FrameStats s;
        renderer.renderFrame(frame, {}, s);
        if (s.footprintCalibration.objects > 0) {
            measuredAt = frame;
            EXPECT_EQ(s.footprintCalibration.objects, 2u);
        }
    }
    EXPECT_GT(measuredAt, 0);
    EXPECT_GE(renderer.report(0).footprint.pixels, static_cast<uint64_t>(o.footprints.minPixels));
    EXPECT_GE(renderer.report(1).footprint.pixels, static_cast<uint64_t>(o.footprints.minPixels));
}

TEST(FootprintCalibration, AStillViewIsNotMeasuredWhileItsFramesReplay) {
    // Its later frames run on the first frame's probed inputs: nothing to gain.
    const Scene scene = twoSpheres(true);
    MultiphaseOptions o;
    o.singlePhaseFrames = false;
    MultiphaseRenderer still(scene, o);
    FrameStats s;
    still.renderFrame(0, {}, s);
    EXPECT_EQ(s.footprintCalibration.objects, 0u);
    EXPECT_EQ(still.report(0).footprintScale, 1.0f);
    // Without the replay, measured.
    o.dynamic.reuseBytes = 0;
    MultiphaseRenderer probing(scene, o);
    probing.renderFrame(0, {}, s);
    EXPECT_EQ(s.footprintCalibration.objects, 2u);
}

TEST(FootprintCalibration, NotMeasuredWhenTooFewFramesFollowOrTheFrameIsBudgeted) {
    const Scene scene = twoSpheres();  // 24 frames
    MultiphaseOptions o;
    o.singlePhaseFrames = false;
    o.footprints.minFrames = 24;
    FrameStats s;
    // Frame 1 has 23 frames from it on; frame 0 has 24.
    MultiphaseRenderer late(scene, o);
    late.renderFrame(1, {}, s);
    EXPECT_EQ(s.footprintCalibration.objects, 0u);
    MultiphaseRenderer early(scene, o);
    early.renderFrame(0, {}, s);
    EXPECT_EQ(s.footprintCalibration.objects, 2u);
    o.frameBudgetSeconds = 10.0;
    MultiphaseRenderer budgeted(scene, o);
    budgeted.renderFrame(0, {}, s);
    EXPECT_EQ(s.footprintCalibration.objects, 0u);
}

}  // namespace
}  // namespace mpshade
