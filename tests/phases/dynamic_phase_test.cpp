// The dynamic phase (dynamic_phase.h) on its own: front-to-back compositing over the
// background at every shading rate against numbers worked by hand, one shading point per
// sample, pixel or 2x2 block, and the band protocol: bands whose probes find tiles missing stay
// undone, hand their tiles back, and once those are filled come out as if the tiles had been
// resident from the start. A still view (view_reuse.h): replayed bit for bit, never across
// a change of view, never from coarser levels, within its budget.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include "phases/dynamic_frame.h"
#include "phases/dynamic_phase.h"
#include "scene/scene.h"
#include "test_support.h"

namespace mpshade {
namespace {

using test::Frame;
using test::kHeight;
using test::kSpp;
using test::kWidth;
using test::shadeWhole;

// Two planes filling the view from above: a half-opaque red one in front of an opaque green
// one, over a blue-grey background. Or, with `back` false, the red one alone.
std::string writeLayeredScene(const std::string& name, bool back) {
    const std::string dir = ::testing::TempDir() + "mpshade_dynamic_" + name + "/";
    std::filesystem::create_directories(dir);
    std::ofstream(dir + "red.sl") << "surface red() { Ci = color(1, 0, 0); Oi = 0.5; }";
    std::ofstream(dir + "green.sl") << "surface green() { Ci = color(0, 1, 0); }";
    std::ofstream json(dir + "scene.json");
    json << R"({ "settings": { "width": 16, "height": 12, "samples_per_pixel": 4, "fps": 1,
      "duration": 1, "background": [0.2, 0.4, 0.6] },
      "camera": { "fov_y": 40, "near": 0.05, "far": 100,
                  "keys": [ { "t": 0, "eye": [0, 4, 0.01], "target": [0, 0, 0] } ] },
      "shaders": { "red": "red.sl", "green": "green.sl" },
      "objects": [
        { "name": "front", "geometry": { "type": "plane", "size": [20, 20] }, "shader": "red",
          "transform": { "translate": [0, 0.5, 0] } })";
    if (back)
        json << R"(,
        { "name": "back", "geometry": { "type": "plane", "size": [20, 20] }, "shader": "green" })";
    json << "] }";
    return dir + "scene.json";
}

// A half-opaque red sphere in the middle of the view: where it is seen, each sample sees it
// twice (front and back), as two layers of one object.
std::string writeSphereScene(const std::string& name) {
    const std::string dir = ::testing::TempDir() + "mpshade_dynamic_" + name + "/";
    std::filesystem::create_directories(dir);
    std::ofstream(dir + "red.sl") << "surface red() { Ci = color(1, 0, 0); Oi = 0.5; }";
    std::ofstream(dir + "scene.json") << R"({ "settings": { "width": 16, "height": 12,
      "samples_per_pixel": 4, "fps": 1, "duration": 1, "background": [0, 0, 0] },
      "camera": { "fov_y": 40, "near": 0.05, "far": 100,
                  "keys": [ { "t": 0, "eye": [0, 0, 4], "target": [0, 0, 0] } ] },
      "shaders": { "red": "red.sl" },
      "objects": [ { "name": "ball", "geometry": { "type": "sphere", "radius": 1 },
                     "shader": "red" } ] })";
    return dir + "scene.json";
}

TEST(DynamicPhase, CompositesFrontToBackOverTheBackgroundAtEveryRate) {
    // Red at half opacity over opaque green: (0.5, 0.5, 0), full coverage. The red one alone
    // over the background (0.2, 0.4, 0.6): 0.5 red + 0.5 background = (0.6, 0.2, 0.3), alpha
    // one half. Back to front (or the background showing through green) would differ.
    const float layered[4] = {0.5f, 0.5f, 0.0f, 1.0f};
    const float alone[4] = {0.6f, 0.2f, 0.3f, 0.5f};
    for (const bool back : {true, false}) {
        Frame f(writeLayeredScene(back ? "layered" : "alone", back), Representation::Facets);
        for (ShadingRate rate : {ShadingRate::Sample, ShadingRate::Pixel, ShadingRate::Quad}) {
            DynamicPhase phase(f.scene);
            phase.begin(f.state, f.drawn, f.layout, f.options(rate));
            EXPECT_TRUE(phase.shade().empty());
            ASSERT_TRUE(phase.complete());
            const float* want = back ? layered : alone;
            const std::vector<float>& rgba = phase.samples().rgba;
            // Per pixel and per quad only each pixel's first sample is written when one
            // point covers the pixel whole (the resolve reads that one).
            const size_t step = rate == ShadingRate::Sample ? 1 : kSpp;
            for (size_t s = 0; s < rgba.size() / 4; s += step)
                for (int k = 0; k < 4; ++k)
                    ASSERT_NEAR(rgba[4 * s + k], want[k], 1e-6f)
                        << "sample " << s << " channel " << k << " rate " << static_cast<int>(rate)
                        << (back ? " layered" : " alone");
            Image image;
            phase.resolve(image);
            for (size_t p = 0; p < image.rgba.size() / 4; ++p)
                for (int k = 0; k < 4; ++k) ASSERT_NEAR(image.rgba[4 * p + k], want[k], 1e-5f);
        }
    }
}

// A plane filling the view from above, shaded by `source`, over the background
// (0.2, 0.4, 0.6).
std::string writePlaneScene(const std::string& name, const std::string& source) {
    const std::string dir = ::testing::TempDir() + "mpshade_dynamic_" + name + "/";
    std::filesystem::create_directories(dir);
    std::ofstream(dir + "plane.sl") << source;
    std::ofstream(dir + "scene.json") << R"({ "settings": { "width": 16, "height": 12,
      "samples_per_pixel": 4, "fps": 1, "duration": 1, "background": [0.2, 0.4, 0.6] },
      "camera": { "fov_y": 40, "near": 0.05, "far": 100,
                  "keys": [ { "t": 0, "eye": [0, 4, 0.01], "target": [0, 0, 0] } ] },
      "shaders": { "plane": "plane.sl" },
      "objects": [ { "name": "plane", "geometry": { "type": "plane", "size": [20, 20] },
                     "shader": "plane" } ] })";
    return dir + "scene.json";
}

TEST(DynamicPhase, OpacityOutsideZeroToOneIsClampedAndANonFiniteResultIsOpaqueBlack) {
    // Oi (2, -1, 0.5) is taken as (1, 0, 0.5): white over the background gives
    // (1, 0.4, 0.5 + 0.5 * 0.6) and alpha 1 - (0 + 1 + 0.5) / 3. Unclamped, green would be
    // 0.4 * 2 - 1 and alpha 1 - (-1 + 2 + 0.5) / 3.
    // Where x > 0.045 the second shader's green is inf - inf: the whole result (every
    // channel, and opacity) becomes opaque black; elsewhere it shades as written.
    struct Case {
        const char* name;
        const char* source;
    };
    const Case cases[] = {
        {"clamped", "surface plane() { Ci = color(1, 1, 1); Oi = color(2, -1, 0.5); }"},
        {"nonfinite",
         "surface plane() { float big = exp(P[0] * 2000.0); "
         "Ci = color(0.25, 0.5 + (big - big), 0.75); Oi = 0.5; }"},
    };
    for (const Case& c : cases) {
        Frame f(writePlaneScene(c.name, c.source), Representation::Facets);
        for (ShadingRate rate : {ShadingRate::Sample, ShadingRate::Pixel}) {
            DynamicPhase phase(f.scene);
            phase.begin(f.state, f.drawn, f.layout, f.options(rate));
            EXPECT_TRUE(phase.shade().empty());
            ASSERT_TRUE(phase.complete());
            Image image;
            phase.resolve(image);
            size_t black = 0, shaded = 0;
            for (size_t p = 0; p < image.rgba.size() / 4; ++p) {
                const float* px = &image.rgba[4 * p];
                for (int k = 0; k < 4; ++k) ASSERT_TRUE(std::isfinite(px[k])) << c.name;
                if (std::string(c.name) == "clamped") {
                    const float want[4] = {1.0f, 0.4f, 0.8f, 0.5f};
                    for (int k = 0; k < 4; ++k) ASSERT_NEAR(px[k], want[k], 1e-5f) << "pixel " << p;
                } else if (px[0] == 0.0f && px[1] == 0.0f && px[2] == 0.0f) {
                    EXPECT_FLOAT_EQ(px[3], 1.0f);
                    ++black;
                } else if (std::fabs(px[0] - (0.125f + 0.1f)) < 1e-5f &&
                           std::fabs(px[1] - (0.25f + 0.2f)) < 1e-5f &&
                           std::fabs(px[2] - (0.375f + 0.3f)) < 1e-5f) {
                    ++shaded;
                }
            }
            if (std::string(c.name) == "nonfinite") {
                // Both regions are large; pixels on their border mix the two.
                EXPECT_GT(black, image.rgba.size() / 4 / 8) << static_cast<int>(rate);
                EXPECT_GT(shaded, image.rgba.size() / 4 / 8) << static_cast<int>(rate);
            }
        }
    }
}

TEST(DynamicPhase, DenormalsAreFlushedWhateverTheCallersFloatMode) {
    // The dynamic shader takes its result through a denormal and back: flushed, the plane
    // is black; kept, about (1 + |I.x|) / 4. Each task the dynamic phase runs flushes
    // denormals (as the static fills and the reference's tracing do), so the frame is the
    // same bits whichever mode the caller had (TBB gives its tasks the mode of the thread
    // that started them, and a static fill can leave that thread's flushed).
#if !defined(__SSE__)
    GTEST_SKIP() << "the float mode is set through SSE's control register";
#else
    Frame f(writePlaneScene("float_mode",
                            "surface plane() { float x = (1 + abs(I[0])) * 1e-30; "
                            "x = x * 1e-10; x = x * 1e30; Ci = color(x * 2.5e9); }"),
            Representation::Facets);
    std::vector<float> samples[2];
    Image images[2];
    for (int flushed = 0; flushed < 2; ++flushed) {
        const test::FloatMode mode(flushed == 1);
        DynamicPhase phase(f.scene);
        phase.begin(f.state, f.drawn, f.layout, f.options(ShadingRate::Sample));
        EXPECT_TRUE(phase.shade().empty());
        samples[flushed] = phase.samples().rgba;
        phase.resolve(images[flushed]);
    }
    // Flushed: the plane black and opaque over the background.
    EXPECT_EQ(samples[1][0], 0.0f);
    ASSERT_EQ(samples[0].size(), samples[1].size());
    EXPECT_EQ(0,
              std::memcmp(samples[0].data(), samples[1].data(), samples[0].size() * sizeof(float)));
    ASSERT_EQ(images[0].rgba.size(), images[1].rgba.size());
    EXPECT_EQ(0, std::memcmp(images[0].rgba.data(), images[1].rgba.data(),
                             images[0].rgba.size() * sizeof(float)));
#endif
}

TEST(DynamicPhase, OneShadingPointPerSamplePixelOrBlockAndSurface) {
    // Both planes cover every sample: per sample, a point per fragment (two per sample);
    // per pixel, two per pixel; per 2x2 block, two per block.
    Frame f(writeLayeredScene("points", true), Representation::Facets);
    const uint64_t samples = uint64_t{kWidth} * kHeight * kSpp;
    const std::pair<ShadingRate, uint64_t> expected[] = {
        {ShadingRate::Sample, 2 * samples},
        {ShadingRate::Pixel, 2 * samples / kSpp},
        {ShadingRate::Quad, 2 * samples / (4 * kSpp)}};
    for (const auto& [rate, points] : expected) {
        for (const bool shortcut : {true, false}) {
            DynamicPhase phase(f.scene);
            DynamicOptions o = f.options(rate);
            o.wholePixelShortcut = shortcut;
            phase.begin(f.state, f.drawn, f.layout, o);
            phase.shade();
            EXPECT_EQ(phase.stats().shadingPoints, points)
                << static_cast<int>(rate) << " shortcut " << shortcut;
            EXPECT_EQ(phase.objectCosts()[0].shadingPoints, points / 2);
            EXPECT_EQ(phase.objectCosts()[1].shadingPoints, points / 2);
        }
    }
}

TEST(DynamicPhase, SurfacesOfOneObjectAtTwoDepthsGetAPointEach) {
    // Per pixel, a point per surface the pixel's samples see, surfaces told apart by object
    // and depth layer: counted here from the visibility buffer, pixel by pixel.
    Frame f(writeSphereScene("sphere"), Representation::Facets);
    DynamicPhase phase(f.scene);
    phase.begin(f.state, f.drawn, f.layout, f.options(ShadingRate::Pixel));
    phase.shade();
    const VisibilityBuffer& vis = phase.visibility();
    ASSERT_GE(vis.layers, 2);
    uint64_t expected = 0, twoLayers = 0;
    for (int py = 0; py < kHeight; ++py)
        for (int px = 0; px < kWidth; ++px) {
            std::vector<std::pair<uint32_t, int>> surfaces;
            for (int k = 0; k < kSpp; ++k) {
                const size_t s = f.layout->index(px, py, k);
                for (int l = 0; l < vis.count[s]; ++l) {
                    const std::pair<uint32_t, int> id{vis.object[s * vis.layers + l], l};
                    if (std::find(surfaces.begin(), surfaces.end(), id) == surfaces.end())
                        surfaces.push_back(id);
                }
            }
            expected += surfaces.size();
            twoLayers += surfaces.size() >= 2;
        }
    EXPECT_GT(twoLayers, 10u);
    EXPECT_EQ(phase.stats().shadingPoints, expected);
}

TEST(DynamicPhase, BandsMissingTilesWaitForThemAndMatchAFrameWithTheTilesResident) {
    // The vase's objects as shader maps with only their always-resident levels (if that):
    // the first pass hands back the tiles its probes found missing and leaves those bands undone;
    // once they are filled, the next pass finishes, bit for bit as a frame shaded with every
    // tile already resident.
    Frame f(test::sourcePath("examples/vase/scene.json"), Representation::ShaderMap, 64, 36);
    DynamicPhase phase(f.scene);
    phase.begin(f.state, f.drawn, f.layout, f.options(ShadingRate::Pixel));
    std::vector<TileRequest> missing = phase.shade();
    ASSERT_FALSE(missing.empty());
    EXPECT_FALSE(phase.complete());
    EXPECT_EQ(phase.stats().shadePasses, 1);
    for (size_t k = 1; k < missing.size(); ++k)  // deduplicated, in order
        EXPECT_TRUE(missing[k - 1].object < missing[k].object ||
                    (missing[k - 1].object == missing[k].object &&
                     missing[k - 1].key.packed() < missing[k].key.packed()));
    int passes = 1;
    while (!missing.empty() && passes < 8) {
        StaticCosts costs;
        f.statics.fill(missing, f.drawn, costs);
        EXPECT_EQ(costs.tilesFilled, missing.size());
        missing = phase.shade();
        ++passes;
    }
    ASSERT_TRUE(phase.complete());
    EXPECT_EQ(phase.stats().probeFallbacks, 0u);
    DynamicPhase again(f.scene);
    again.begin(f.state, f.drawn, f.layout, f.options(ShadingRate::Pixel));
    EXPECT_TRUE(again.shade().empty());  // every tile resident now
    EXPECT_EQ(again.stats().shadingPoints, phase.stats().shadingPoints);
    EXPECT_EQ(again.samples().rgba, phase.samples().rgba);
    // Every part of shading was timed, and the parts (CPU time over the threads) fit in the
    // pass's wall time on every thread the machine has.
    const DynamicFrameStats::ShadeParts& parts = again.stats().shadeParts;
    EXPECT_GT(parts.points, 0.0);
    EXPECT_GT(parts.interpolate, 0.0);
    EXPECT_GT(parts.probe, 0.0);
    EXPECT_GT(parts.kernel, 0.0);
    EXPECT_GT(parts.composite, 0.0);
    const double threads = std::max(1, tbb::this_task_arena::max_concurrency());
    EXPECT_LE(parts.points + parts.interpolate + parts.probe + parts.kernel + parts.composite,
              again.stats().shadeSeconds * threads);
}

TEST(DynamicPhase, AcceptingFallbacksFinishesInOnePassFromCoarserLevels) {
    Frame f(test::sourcePath("examples/vase/scene.json"), Representation::ShaderMap, 64, 36);
    DynamicPhase phase(f.scene);
    phase.begin(f.state, f.drawn, f.layout, f.options(ShadingRate::Pixel));
    const std::vector<TileRequest> missing = phase.shade(true);
    EXPECT_TRUE(phase.complete());
    EXPECT_FALSE(missing.empty());
    EXPECT_GT(phase.stats().probeFallbacks, 0u);
    EXPECT_LE(phase.stats().probeFallbacks, phase.stats().probes);
    for (float v : phase.samples().rgba) ASSERT_TRUE(std::isfinite(v));
}

// The lamplight example: a still camera over the vase and floor, a point light circling.
constexpr const char* kLamplight = "examples/vase/lamplight.json";

TEST(DynamicPhase, AStillViewShadesItsKeptInputsBitForBit) {
    // Frame 0 keeps nothing (its bands wait for tiles), frame 1 keeps every band's inputs,
    // frames 2 on run the dynamic shader alone on them: no warp, no rasterization, no
    // probe. Each frame equals a phase that never keeps anything, and the light's motion
    // shows (so a replay of last frame's colours would not pass).
    Frame f(test::sourcePath(kLamplight), Representation::ShaderMap, 64, 36);
    DynamicPhase kept(f.scene), fresh(f.scene);
    DynamicOptions never = f.options(ShadingRate::Sample);
    never.reuseBytes = 0;
    std::vector<std::vector<float>> frames;
    for (int t = 0; t < 5; ++t) {
        SCOPED_TRACE(t);
        const FrameState state = frameStateAt(f.resources, t * 6, 64, 36, kSpp);
        shadeWhole(f, kept, state, f.options(ShadingRate::Sample));
        // (A band shaded again after a fill groups its points into other batches, and
        // Feline's setup shared along a batch may then differ in the last bits: the phase
        // that keeps nothing shades second, every tile resident, as the kept one's bands
        // that kept their inputs did.)
        shadeWhole(f, fresh, state, never);
        const DynamicFrameStats& s = kept.stats();
        EXPECT_EQ(s.viewReused, t >= 1);
        if (t == 0) {
            EXPECT_EQ(s.pointsReplayed, 0u);
        } else if (t == 1) {
            EXPECT_LT(s.pointsReplayed, s.shadingPoints);  // only bands kept at frame 0
        } else {
            EXPECT_EQ(s.pointsReplayed, s.shadingPoints);
        }
        EXPECT_GT(s.shadingPoints, 1000u);
        if (t >= 2) {
            EXPECT_EQ(s.probes, 0u);
            EXPECT_EQ(s.verticesWarped, 0u);
            EXPECT_EQ(s.raster.fragments, 0u);
        }
        EXPECT_FALSE(fresh.stats().viewReused);
        EXPECT_EQ(fresh.stats().pointsReplayed, 0u);
        ASSERT_EQ(kept.samples().rgba, fresh.samples().rgba);
        frames.push_back(kept.samples().rgba);
    }
    EXPECT_NE(frames[2], frames[3]);
    EXPECT_NE(frames[3], frames[4]);
}

TEST(DynamicPhase, WithoutKeepingTheFirstViewReplaysFromTheThirdStillFrame) {
    // keepFirstView off (a caller whose camera moves from the start): frame 0 keeps nothing,
    // frame 1, still since frame 0, shades afresh and keeps, frame 2 replays every point --
    // the same bits as a phase that keeps nothing. (Lamplight's camera holds still; its
    // light moves, which the view does not include.)
    Frame f(test::sourcePath(kLamplight), Representation::ShaderMap, 64, 36);
    DynamicPhase kept(f.scene), fresh(f.scene);
    DynamicOptions late = f.options(ShadingRate::Sample);
    late.keepFirstView = false;
    DynamicOptions never = f.options(ShadingRate::Sample);
    never.reuseBytes = 0;
    for (int t = 0; t < 3; ++t) {
        SCOPED_TRACE(t);
        const FrameState state = frameStateAt(f.resources, t, 64, 36, kSpp);
        shadeWhole(f, kept, state, late);
        shadeWhole(f, fresh, state, never);
        const DynamicFrameStats& s = kept.stats();
        EXPECT_EQ(s.viewReused, t >= 1);  // the view held still; what replays is below
        EXPECT_EQ(s.pointsReplayed, t == 2 ? s.shadingPoints : 0u);
        EXPECT_GT(s.shadingPoints, 1000u);
        ASSERT_EQ(kept.samples().rgba, fresh.samples().rgba);
    }
}

TEST(DynamicPhase, TheSameFrameAgainKeepsOnlyWhereAFirstFrameWould) {
    // A frame rendered again (play's first frame after its pre-roll rendered it) sees what
    // the last render did, but says nothing of the next frame: with keepFirstView off it
    // keeps nothing -- keeping had been 40-60 ms of allocation in play's first frame at
    // 1280x720, a deadline missed for inputs the moving camera never replays. The frame
    // after it, still since, keeps; the one after that replays. With keepFirstView on, the
    // same frame again keeps and the next replays all.
    Frame f(test::sourcePath(kLamplight), Representation::ShaderMap, 64, 36);
    for (const bool keepFirst : {false, true}) {
        SCOPED_TRACE(keepFirst);
        DynamicPhase phase(f.scene);
        DynamicOptions o = f.options(ShadingRate::Sample);
        o.keepFirstView = keepFirst;
        const FrameState first = frameStateAt(f.resources, 0, 64, 36, kSpp);
        shadeWhole(f, phase, first, o);
        shadeWhole(f, phase, first, o);  // the same frame again
        EXPECT_TRUE(phase.stats().viewReused);
        // Kept on: the bands that kept their inputs at the first render (those that found
        // every tile) replay.
        if (keepFirst)
            EXPECT_GT(phase.stats().pointsReplayed, 0u);
        else
            EXPECT_EQ(phase.stats().pointsReplayed, 0u);
        const FrameState second = frameStateAt(f.resources, 1, 64, 36, kSpp);
        shadeWhole(f, phase, second, o);
        EXPECT_TRUE(phase.stats().viewReused);
        const uint64_t points = phase.stats().shadingPoints;
        EXPECT_GT(points, 1000u);
        EXPECT_EQ(phase.stats().pointsReplayed, keepFirst ? points : 0u);
        const FrameState third = frameStateAt(f.resources, 2, 64, 36, kSpp);
        shadeWhole(f, phase, third, o);
        EXPECT_EQ(phase.stats().pointsReplayed, phase.stats().shadingPoints);
    }
}

TEST(DynamicPhase, AnyChangeOfTheViewShadesAfresh) {
    // After two still frames, each change the inputs depend on: the camera, an object's
    // placement, a representation built again, the footprint. None replays; each equals a
    // phase that keeps nothing (both shading with every tile resident: see above).
    Frame f(test::sourcePath(kLamplight), Representation::ShaderMap, 64, 36);
    DynamicOptions never = f.options(ShadingRate::Sample);
    never.reuseBytes = 0;
    for (int change = 0; change < 4; ++change) {
        SCOPED_TRACE(change);
        DynamicPhase kept(f.scene), fresh(f.scene);
        FrameState state = frameStateAt(f.resources, 0, 64, 36, kSpp);
        shadeWhole(f, kept, state, f.options(ShadingRate::Sample));
        shadeWhole(f, kept, state, f.options(ShadingRate::Sample));
        DynamicOptions o = f.options(ShadingRate::Sample);
        std::unique_ptr<ObjectRepresentation> rebuilt;
        std::vector<const ObjectRepresentation*> drawn = f.drawn;
        if (change == 0) state.camera.eye.x += 1e-3f;
        if (change == 1) state.objects[0].objectToWorld[3][0] += 1e-3f;
        if (change == 2) {
            StaticCosts costs;
            rebuilt = f.statics.build(0, Representation::ShaderMap, state.objects[0], state.camera,
                                      state.uniforms[0], f.reps[0].get(), costs);
            f.drawn[0] = rebuilt.get();
        }
        if (change == 3) o.footprintScale = never.footprintScale = 1.5f;
        DynamicPhase warm(f.scene);
        shadeWhole(f, warm, state, never);  // both below then find every tile resident
        shadeWhole(f, kept, state, o);
        shadeWhole(f, fresh, state, never);
        f.drawn = drawn;
        EXPECT_FALSE(kept.stats().viewReused);
        EXPECT_EQ(kept.stats().pointsReplayed, 0u);
        EXPECT_GT(kept.stats().probes, 0u);
        EXPECT_EQ(kept.samples().rgba, fresh.samples().rgba);
    }
}

TEST(DynamicPhase, BandsThatReadCoarserLevelsKeepNothing) {
    // Two still frames accepting fallbacks with no tile filled, then every missing tile
    // filled: the third frame must read the finer levels, as a phase that keeps nothing
    // does, not replay what the coarser ones gave.
    Frame f(test::sourcePath(kLamplight), Representation::ShaderMap, 64, 36);
    DynamicPhase kept(f.scene), fresh(f.scene);
    const FrameState state = frameStateAt(f.resources, 0, 64, 36, kSpp);
    shadeWhole(f, kept, state, f.options(ShadingRate::Sample), true);
    shadeWhole(f, kept, state, f.options(ShadingRate::Sample), true);
    EXPECT_GT(kept.stats().probeFallbacks, 0u);
    const uint64_t points = kept.stats().shadingPoints;
    shadeWhole(f, fresh, state, f.options(ShadingRate::Sample));  // fills every missing tile
    DynamicOptions never = f.options(ShadingRate::Sample);
    never.reuseBytes = 0;
    shadeWhole(f, fresh, state, never);
    shadeWhole(f, kept, state, f.options(ShadingRate::Sample));
    EXPECT_TRUE(kept.stats().viewReused);
    EXPECT_LT(kept.stats().pointsReplayed, points);
    EXPECT_EQ(kept.stats().probeFallbacks, 0u);
    EXPECT_EQ(kept.samples().rgba, fresh.samples().rgba);
}

TEST(DynamicPhase, KeptInputsStayWithinTheirBudget) {
    // A budget smaller than any band's inputs: nothing is kept, nothing replayed, the frames
    // the same.
    Frame f(test::sourcePath(kLamplight), Representation::ShaderMap, 64, 36);
    DynamicPhase tight(f.scene), fresh(f.scene);
    DynamicOptions o = f.options(ShadingRate::Sample), never = o;
    o.reuseBytes = 64;
    never.reuseBytes = 0;
    for (int t = 0; t < 3; ++t) {
        const FrameState state = frameStateAt(f.resources, t, 64, 36, kSpp);
        shadeWhole(f, tight, state, o);
        shadeWhole(f, fresh, state, never);
        EXPECT_EQ(tight.stats().pointsReplayed, 0u);
        EXPECT_EQ(tight.samples().rgba, fresh.samples().rgba);
    }
}

}  // namespace
}  // namespace mpshade
