// What the representation planner feeds the cost estimate: how often combined facets would
// be diced again along the planned frames (an eye approaching by steps worked out by hand),
// and the always-resident tiles a map would hold (against a map built with them).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "controller/representation_planner.h"
#include "test_support.h"

namespace mpshade {
namespace {

// A sphere of radius 0.5 at the origin (its bounds' half diagonal r = 0.866), the eye on
// the z axis at r + 10 - 0.6 k in frame k = 0..7: the distance the planner measures, from
// the eye to the bounding sphere, is 10, 9.4, 8.8, ..., 5.8.
std::string writeApproachScene() {
    const std::string dir = ::testing::TempDir() + "mpshade_planner_approach/";
    std::filesystem::create_directories(dir);
    std::ofstream(dir + "grey.sl") << "surface grey() { Ci = color(noise(P * 8)); }";
    std::ofstream json(dir + "scene.json");
    json << R"({ "settings": { "width": 64, "height": 48, "samples_per_pixel": 1, "fps": 1,
      "duration": 8 }, "camera": { "fov_y": 40, "near": 0.05, "far": 100, "keys": [)";
    const double r = 0.5 * std::sqrt(3.0);
    for (int k = 0; k < 8; ++k)
        json << (k ? ", " : "") << R"({ "t": )" << k << R"(, "eye": [0, 0, )" << r + 10.0 - 0.6 * k
             << R"(], "target": [0, 0, 0] })";
    json << R"(] }, "shaders": { "grey": "grey.sl" },
      "objects": [ { "name": "ball", "geometry": { "type": "sphere", "radius": 0.5 },
                     "shader": "grey", "range": { "distance_factor": 1.25, "angle": 20 } } ] })";
    return dir + "scene.json";
}

TEST(RepresentationPlanner, CombinedFacetsDicedAgainEachTimeTheEyeComesFivePercentCloser) {
    // From frame 0 (distance 10), each later frame is more than 5% nearer than the last
    // dicing (9.4 < 9.5, 8.8 < 8.93, ..., 5.8 < 6.08): a run per frame, 8 in all. From frame
    // 6 (6.4): frame 7 only, 2 in all.
    const Scene scene = loadScene(writeApproachScene());
    const SceneResources resources(scene, SceneResources::RayScenes::ForOcclusion);
    const StaticPhase statics(scene, resources);
    RepresentationPlanner planner(scene, statics, RepresentationCostModel{}, std::nullopt);
    planner.plan(0, 8, 64, 48);
    const ObjectSlot slot;
    for (const auto& [frame, runs] : {std::pair{0, 8}, std::pair{6, 2}, std::pair{7, 1}}) {
        const FrameState state = frameStateAt(resources, frame, 64, 48, 1);
        const ObjectCostInputs in =
            planner.costInputs(0, slot, frame, state.objects[0], state.camera, 1, {});
        EXPECT_EQ(in.combinedRuns, runs) << "from frame " << frame;
        EXPECT_EQ(in.frames, 8 - frame);
    }
}

TEST(RepresentationPlanner, PinnedTilesAreWhatAMapHoldsAlwaysResident) {
    // The vase's objects, each built as a map with its always-resident levels filled: the
    // planner's estimate is the tiles the map then holds.
    const Scene scene = loadScene(test::sourcePath("examples/vase/scene.json"));
    const SceneResources resources(scene, SceneResources::RayScenes::ForOcclusion);
    StaticPhaseOptions options;
    options.shaderMap.fillPinnedUpFront = true;
    const StaticPhase statics(scene, resources, options);
    const RepresentationPlanner planner(scene, statics, RepresentationCostModel{}, std::nullopt);
    const FrameState state = frameStateAt(resources, 0, 96, 54, 1);
    int maps = 0;
    for (size_t i = 0; i < scene.objects.size(); ++i) {
        if (scene.objects[i].shadermapResolution > 0) continue;  // the estimate is the default's
        StaticCosts costs;
        const auto rep = statics.build(i, Representation::ShaderMap, state.objects[i], state.camera,
                                       state.uniforms[i], nullptr, costs);
        if (!rep->map) continue;  // nothing static stored
        const ObjectSlot slot;
        const ObjectCostInputs in =
            planner.costInputs(i, slot, 0, state.objects[i], state.camera, 1, {});
        EXPECT_EQ(in.pinnedTiles, static_cast<double>(rep->map->residentTiles()))
            << scene.objects[i].name;
        ++maps;
    }
    EXPECT_GT(maps, 0);
}

// A camera 10 away from a 0.1 x 0.1 plane at the origin (normal +y), looking at its centre
// from `elevation` degrees above it: every sample sees it at about that angle.
double elongationFrom(float elevationDegrees, float levelAnisotropy, bool lookAway = false) {
    const Surface plane = Plane{0.1f, 0.1f};
    const float a = glm::radians(elevationDegrees);
    CameraState camera;
    camera.eye = 10.0f * glm::vec3(0.0f, std::sin(a), std::cos(a));
    camera.forward = glm::normalize(-camera.eye) * (lookAway ? -1.0f : 1.0f);
    camera.right = glm::normalize(glm::cross(camera.forward, glm::vec3(1e-3f, 1.0f, 0.0f)));
    camera.up = glm::cross(camera.right, camera.forward);
    camera.tanHalfFovY = std::tan(glm::radians(20.0f));
    camera.width = 64;
    camera.height = 48;
    camera.aspect = 64.0f / 48.0f;
    ObjectState state;
    state.eye = camera.eye;
    return footprintElongation(plane, state, camera, levelAnisotropy);
}

TEST(RepresentationPlanner, FootprintElongationIsOneOverTheCosineUpToTheCap) {
    // Seen at elevation e the view ray meets the normal at cos = sin e: footprints are 1 / sin e
    // times longer than wide, up to the probe's levelAnisotropy.
    EXPECT_NEAR(elongationFrom(90.0f, 12.0f), 1.0, 0.01);
    EXPECT_NEAR(elongationFrom(30.0f, 12.0f), 2.0, 0.03);
    EXPECT_NEAR(elongationFrom(10.0f, 12.0f), 1.0 / std::sin(glm::radians(10.0)), 0.15);
    EXPECT_NEAR(elongationFrom(3.0f, 12.0f), 12.0, 1e-9);  // 19.1, capped
    EXPECT_NEAR(elongationFrom(3.0f, 0.0f), 1.0 / std::sin(glm::radians(3.0)), 0.6);  // no cap
    EXPECT_DOUBLE_EQ(elongationFrom(30.0f, 12.0f, true), 1.0);  // behind the eye: nothing seen
}

}  // namespace
}  // namespace mpshade
