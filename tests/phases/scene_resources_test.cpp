// SceneResources' ray scenes: only the objects whose shaders trace occlusion get one (unless
// all are asked for), none is built before a ray needs it, and buildRayScenes() builds them
// all ahead (playback's pre-roll, so no frame pays for one).
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "geometry/ray_scene.h"
#include "phases/scene_resources.h"
#include "scene/scene.h"

namespace mpshade {
namespace {

std::string writeScene() {
    const std::string dir = ::testing::TempDir() + "mpshade_scene_resources_" +
                            ::testing::UnitTest::GetInstance()->current_test_info()->name() + "/";
    std::filesystem::create_directories(dir);
    std::ofstream(dir + "ao.sl") << "surface ao() { Ci = color(occlusion(P, N, 4)); }";
    std::ofstream(dir + "flat.sl") << "surface flat() { Ci = color(0.5); }";
    std::ofstream(dir + "scene.json") << R"({ "settings": { "width": 32, "height": 18,
      "samples_per_pixel": 1, "fps": 1, "duration": 1 },
      "camera": { "fov_y": 40, "near": 0.05, "far": 100,
                  "keys": [ { "t": 0, "eye": [0, 3, 4], "target": [0, 0, 0] } ] },
      "shaders": { "ao": "ao.sl", "flat": "flat.sl" },
      "objects": [
        { "name": "floor", "geometry": { "type": "plane", "size": [4, 4] }, "shader": "ao" },
        { "name": "ball", "geometry": { "type": "sphere", "radius": 0.5 }, "shader": "flat" } ] })";
    return dir + "scene.json";
}

TEST(SceneResources, RayScenesAreBuiltAtTheirFirstRayOrAheadWhenAsked) {
    const Scene scene = loadScene(writeScene());
    const SceneResources forOcclusion(scene, SceneResources::RayScenes::ForOcclusion);
    ASSERT_EQ(forOcclusion.objectCount(), 2u);
    const SurfaceRayScene* floor = forOcclusion.object(0).rayScene;
    ASSERT_NE(floor, nullptr);
    EXPECT_EQ(forOcclusion.object(1).rayScene, nullptr);  // its shader traces no ray
    EXPECT_FALSE(floor->built());
    forOcclusion.buildRayScenes();
    EXPECT_TRUE(floor->built());
    EXPECT_GT(floor->triangleCount(), 0u);

    const SceneResources all(scene, SceneResources::RayScenes::All);
    ASSERT_NE(all.object(1).rayScene, nullptr);
    EXPECT_FALSE(all.object(0).rayScene->built());
    EXPECT_FALSE(all.object(1).rayScene->built());
    all.buildRayScenes();
    EXPECT_TRUE(all.object(0).rayScene->built());
    EXPECT_TRUE(all.object(1).rayScene->built());
}

}  // namespace
}  // namespace mpshade
