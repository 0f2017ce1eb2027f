// The dynamic phase (dynamic_phase.h) on its own: front-to-back compositing over the
// background at every shading rate against numbers worked by hand, one shading point per
// sample, pixel or 2x2 block, and the band protocol: bands whose probes find tiles missing stay
// undone, hand their tiles back, and once those are filled come out as if the tiles had been
// resident from the start.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "phases/dynamic_phase.h"
#include "phases/static_phase.h"
#include "scene/scene.h"
#include "test_support.h"

namespace mpshade {
namespace {

constexpr int kWidth = 16, kHeight = 12, kSpp = 4;

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

// A scene's objects built for frame 0 (each as `kind`), and a dynamic phase over them.
struct Frame {
    Scene scene;
    SceneResources resources{scene, SceneResources::RayScenes::ForOcclusion};
    StaticPhase statics{scene, resources};
    FrameState state;
    std::vector<std::unique_ptr<ObjectRepresentation>> reps;
    std::vector<const ObjectRepresentation*> drawn;
    std::shared_ptr<const SampleLayout> layout;

    Frame(const std::string& path, Representation kind, int width = kWidth, int height = kHeight)
        : scene(loadScene(path)) {
        state = frameStateAt(resources, 0, width, height, kSpp);
        for (size_t i = 0; i < scene.objects.size(); ++i) {
            StaticCosts costs;
            reps.push_back(statics.build(i, kind, state.objects[i], state.camera, state.uniforms[i],
                                         nullptr, costs));
            drawn.push_back(reps.back().get());
        }
        layout = std::make_shared<const SampleLayout>(width, height, kSpp, 7u);
    }
    DynamicOptions options(ShadingRate rate) const {
        DynamicOptions o;
        o.shadingRate = rate;
        return o;
    }
};

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

}  // namespace
}  // namespace mpshade
