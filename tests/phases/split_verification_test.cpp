// Verifying a split (split_verification.h): the examples' splits agree with their whole
// shaders to rounding, and a bake() of time measures exactly the error its frozen value
// makes, worked out here from the frame times.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "phases/split_verification.h"
#include "scene/scene.h"
#include "test_support.h"

namespace mpshade {
namespace {

TEST(SplitVerification, TheExamplesSplitsAgreeWithTheirWholeShaders) {
    for (const char* path : {"examples/vase/scene.json", "examples/teapot/scene.json"}) {
        SCOPED_TRACE(path);
        const Scene scene = loadScene(test::sourcePath(path));
        const SceneResources resources(scene, SceneResources::RayScenes::ForOcclusion);
        const StaticPhase statics(scene, resources);
        for (size_t i = 0; i < scene.objects.size(); ++i) {
            const SplitVerification v = verifySplit(statics, resources, i, {1024, 4});
            EXPECT_GT(v.points, 100);
            EXPECT_EQ(v.frames, 4);
            ASSERT_EQ(v.outputs.size(), 6u);
            EXPECT_LE(v.maxRelative(), 1e-5) << scene.objects[i].name;
            for (const SplitDifference& c : v.channels) EXPECT_EQ(c.maxAbs, 0.0) << c.name;
        }
    }
}

TEST(SplitVerification, ABakeOfTimeCostsWhatItsFrozenValueMisses) {
    // Ci = bake(sin(3 time)) on a sphere, 24 frames at 12 fps: the static run at frame 0
    // stores sin(0) = 0, so frame f is off by |sin(3 f / 12)| at every point. Over the
    // verified frames 0, 23/3 rounded, ... 23: the largest of those.
    const std::string dir = ::testing::TempDir() + "mpshade_split/";
    std::filesystem::create_directories(dir);
    std::ofstream(dir + "b.sl") << "surface b() { Ci = color(bake(sin(3 * time))); }";
    std::ofstream(dir + "s.json") << R"({"settings": {"width": 32, "height": 18, "fps": 12,
      "duration": 2}, "camera": {"eye": [0, 0, 5], "target": [0, 0, 0]},
      "shaders": {"b": "b.sl"},
      "objects": [{"name": "o", "geometry": {"type": "sphere", "radius": 1}, "shader": "b"}]})";
    const Scene scene = loadScene(dir + "s.json");
    ASSERT_EQ(scene.frameCount(), 24);
    const SceneResources resources(scene, SceneResources::RayScenes::ForOcclusion);
    const StaticPhase statics(scene, resources);
    const SplitVerification v = verifySplit(statics, resources, 0, {256, 4});
    double expected = 0.0;
    int worstFrame = 0;
    for (int k = 0; k < 4; ++k) {
        const int f = static_cast<int>(std::lround(k * 23.0 / 3.0));
        const double off = std::fabs(std::sin(3.0 * f / 12.0));
        if (off > expected) expected = off, worstFrame = f;
    }
    EXPECT_NEAR(v.outputs[0].maxAbs, expected, 1e-5);
    EXPECT_EQ(v.outputs[0].worst.frame, worstFrame);
    EXPECT_NEAR(v.maxRelative(), expected, 1e-5);  // |a - b| / 1 for values within [-1, 1]
    ASSERT_EQ(v.channels.size(), 1u);
    EXPECT_NEAR(v.channels[0].maxAbs, expected, 1e-5);  // the stored value's own drift
    EXPECT_EQ(v.outputs[3].maxAbs, 0.0);                // Oi is not baked
}

}  // namespace
}  // namespace mpshade
