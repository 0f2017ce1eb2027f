// The shader-map precision check (map_precision.h): binary16 for a stored colour the dynamic
// part scales, float for a stored phase it takes the sine of and for values past half's
// range; the tolerance's boundary; the verdict kept in a store and read back.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "phases/map_precision.h"
#include "phases/static_phase.h"
#include "scene/scene.h"
#include "shadermaps/tile_store.h"

namespace mpshade {
namespace {

// A sphere with shader `source`, two seconds at 12 fps so `time` is dynamic.
std::string writeScene(const std::string& name, const std::string& source) {
    const std::string dir = ::testing::TempDir() + "mpshade_map_precision_" + name + "/";
    std::filesystem::create_directories(dir);
    std::ofstream(dir + "s.sl") << source;
    std::ofstream(dir + "scene.json") << R"({"settings": {"width": 64, "height": 36, "fps": 12,
      "duration": 2}, "camera": {"eye": [0, 0, 5], "target": [0, 0, 0]},
      "lights": [{"type": "distant", "direction": [-1, -1, -1], "color": [1, 1, 1]}],
      "shaders": {"s": "s.sl"},
      "objects": [{"name": "o", "geometry": {"type": "sphere", "radius": 1}, "shader": "s"}]})";
    return dir + "scene.json";
}

MapPrecisionCheck checkScene(const std::string& name, const std::string& source,
                             const MapPrecisionOptions& options = {}) {
    const Scene scene = loadScene(writeScene(name, source));
    const SceneResources resources(scene, SceneResources::RayScenes::ForOcclusion);
    const StaticPhase statics(scene, resources);
    EXPECT_FALSE(statics.shading(0).factored.staticPart.channelOutputs.empty());
    const FrameState state = frameStateAt(resources, 0, 64, 36, 1);
    return checkHalfPrecision(statics, *scene.objects[0].surface, 0, state.uniforms[0], options);
}

// fbm makes each stored value cost more than repeating it would save (so it is stored).
const char* kScaledColour = R"(surface s() {
    color Cd = color(0.6, 0.4, 0.2) * (0.5 + 0.5 * fbm(P * 3.0, 6));
    Ci = Cd * diffuse(N) + 0.5 * specular(N, -I, 0.3);
})";

TEST(MapPrecision, AStoredColourTheLightScalesIsHalf) {
    const MapPrecisionCheck c = checkScene("colour", kScaledColour);
    EXPECT_TRUE(c.half) << c.reason;
    EXPECT_GT(c.points, 100);
    // One rounding of the stored value, relative 2^-11 at most, carried through a product
    // with the light and a sum with a term that did not move.
    EXPECT_GT(c.largestChange, 0.0);
    EXPECT_LE(c.largestChange, std::ldexp(1.0, -11) * (1.0 + 1e-6));
    EXPECT_LE(c.largestValue, 1.0);
    EXPECT_EQ(c.reason.rfind("half: ", 0), 0u) << c.reason;
}

TEST(MapPrecision, AStoredPhaseTheDynamicPartTakesTheSineOfIsFloat) {
    // phase reaches about 200 + 1, where binary16's step is 1/8: its rounding of up to 1/16
    // moves 0.5 + 0.5 sin by up to 1/32, sixteen times the tolerance.
    const MapPrecisionCheck c = checkScene("phase", R"(surface s() {
        float phase = 200.0 * P[0] + fbm(P * 3.0, 6);
        Ci = color(0.5 + 0.5 * sin(phase + 40.0 * time));
    })");
    EXPECT_FALSE(c.half) << c.reason;
    EXPECT_LE(c.largestValue, 4096.0);  // within range: the change alone decides
    EXPECT_GT(c.largestChange, 1.0 / 512.0);
    EXPECT_LE(c.largestChange, 0.5 * std::ldexp(c.largestValue, -11) + 1e-6);
    EXPECT_NE(c.reason.find("moved an output"), std::string::npos) << c.reason;
}

TEST(MapPrecision, ValuesPastHalfsRangeAreFloat) {
    const MapPrecisionCheck c = checkScene("range", R"(surface s() {
        float big = 1e5 * (2.0 + fbm(P * 3.0, 6));
        Ci = color(big * (1e-5 + 1e-6 * sin(time)));
    })");
    EXPECT_FALSE(c.half) << c.reason;
    EXPECT_GT(c.largestValue, 65504.0);
    EXPECT_TRUE(std::isinf(c.largestChange));  // the rounded value is infinite
    EXPECT_NE(c.reason.find("reaches"), std::string::npos) << c.reason;
}

TEST(MapPrecision, TheToleranceHoldsAtItsOwnValue) {
    const MapPrecisionCheck measured = checkScene("edge", kScaledColour);
    ASSERT_GT(measured.largestChange, 0.0);
    MapPrecisionOptions at;
    at.tolerance = measured.largestChange;
    EXPECT_TRUE(checkScene("edge", kScaledColour, at).half);
    MapPrecisionOptions below = at;
    below.tolerance = std::nextafter(measured.largestChange, 0.0);
    EXPECT_FALSE(checkScene("edge", kScaledColour, below).half);
    MapPrecisionOptions valueAt;
    valueAt.maxValue = measured.largestValue;
    EXPECT_TRUE(checkScene("edge", kScaledColour, valueAt).half);
    valueAt.maxValue = std::nextafter(measured.largestValue, 0.0);
    EXPECT_FALSE(checkScene("edge", kScaledColour, valueAt).half);
}

TEST(MapPrecision, TheMapIsMadeAsCheckedAndTheVerdictIsKeptInTheStore) {
    const Scene scene = loadScene(writeScene("store", kScaledColour));
    const SceneResources resources(scene, SceneResources::RayScenes::ForOcclusion);
    const FrameState state = frameStateAt(resources, 0, 64, 36, 1);
    const std::string root = ::testing::TempDir() + "mpshade_map_precision_store_root";
    std::filesystem::remove_all(root);
    StaticPhaseOptions options;
    options.store = std::make_shared<TileStore>(root);
    for (int run = 0; run < 2; ++run) {
        const StaticPhase statics(scene, resources, options);
        StaticCosts costs;
        const std::unique_ptr<ObjectRepresentation> rep =
            statics.build(0, Representation::ShaderMap, state.objects[0], state.camera,
                          state.uniforms[0], nullptr, costs);
        ASSERT_TRUE(rep->map);
        EXPECT_TRUE(rep->map->options().halfPrecision) << run;
        ASSERT_TRUE(statics.precisionCheck(0).has_value());
        const MapPrecisionCheck c = *statics.precisionCheck(0);
        EXPECT_TRUE(c.half);
        EXPECT_GT(c.largestChange, 0.0);
        EXPECT_EQ(c.reason.find("in the store") != std::string::npos, run == 1) << c.reason;
    }
    // An object that says float is not checked.
    Scene asFloat = scene;
    asFloat.objects[0].shadermapPrecision = MapPrecision::Float;
    const SceneResources floatResources(asFloat, SceneResources::RayScenes::ForOcclusion);
    const StaticPhase statics(asFloat, floatResources);
    StaticCosts costs;
    const std::unique_ptr<ObjectRepresentation> rep =
        statics.build(0, Representation::ShaderMap, state.objects[0], state.camera,
                      state.uniforms[0], nullptr, costs);
    ASSERT_TRUE(rep->map);
    EXPECT_FALSE(rep->map->options().halfPrecision);
    EXPECT_FALSE(statics.precisionCheck(0).has_value());
}

}  // namespace
}  // namespace mpshade
