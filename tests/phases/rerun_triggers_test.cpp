// When an object goes back through the static phase, and why: the fiducial that crossed
// its threshold, measured here independently from the scene's camera.
#include <cmath>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "phases/multiphase_renderer.h"
#include "scene/scene_state.h"
#include "test_support.h"

namespace mpshade {
namespace {

RenderOptions tiny() {
    RenderOptions r;
    r.width = 64;
    r.height = 36;
    return r;
}

MultiphaseOptions everyFrame() {
    MultiphaseOptions o;
    o.singlePhaseFrames = false;
    return o;
}

// The vase orbits 1.875 degrees a frame; the floor's range is 10 degrees (its view
// direction, its patches being frustum culled), the vase's 30.
TEST(RerunTriggers, AnOrbitWithinTheRangeRunsNothingAfterTheFirstFrame) {
    const Scene scene = loadScene(test::sourcePath("examples/vase/scene.json"));
    MultiphaseRenderer renderer(scene, everyFrame());
    FrameStats stats;
    renderer.renderFrame(0, tiny(), stats);
    ASSERT_EQ(stats.staticRunsDue.size(), 2u);
    for (const StaticRunDue& d : stats.staticRunsDue) {
        EXPECT_EQ(d.cause, StaticRunDue::FirstSeen);
        EXPECT_FALSE(d.deferred);
    }
    for (int frame = 1; frame <= 5; ++frame) {
        renderer.renderFrame(frame, tiny(), stats);
        EXPECT_EQ(stats.staticRuns, 0) << frame;
        EXPECT_TRUE(stats.staticRunsDue.empty()) << frame;
    }
}

TEST(RerunTriggers, LeavingTheRangeRunsExactlyTheObjectsThatLeftItAndSaysWhy) {
    const Scene scene = loadScene(test::sourcePath("examples/vase/scene.json"));
    MultiphaseRenderer renderer(scene, everyFrame());
    FrameStats stats;
    const int floorIndex = scene.objects[0].name == "floor" ? 0 : 1;
    for (int frame = 0; frame <= 6; ++frame) renderer.renderFrame(frame, tiny(), stats);
    // Frame 6: the floor's view direction has turned past 10 degrees from frame 0's; the
    // vase, 30 degrees, stays.
    ASSERT_EQ(stats.staticRunsDue.size(), 1u);
    const StaticRunDue& d = stats.staticRunsDue[0];
    EXPECT_EQ(d.object, static_cast<uint32_t>(floorIndex));
    EXPECT_EQ(d.cause, StaticRunDue::ViewDirection);
    EXPECT_EQ(d.threshold, 10.0f);
    EXPECT_EQ(stats.staticRuns, 1);
    const glm::vec3 f0 = cameraAt(scene, scene.frameTime(0), 64, 36).forward;
    const glm::vec3 f6 = cameraAt(scene, scene.frameTime(6), 64, 36).forward;
    const float turned = glm::degrees(std::acos(glm::dot(f0, f6)));
    EXPECT_GT(turned, 10.0f);
    EXPECT_NEAR(d.measured, turned, 0.05f);
    // The floor was re-run at frame 6: frame 7 is in its new range.
    renderer.renderFrame(7, tiny(), stats);
    EXPECT_TRUE(stats.staticRunsDue.empty());
}

TEST(RerunTriggers, ANewImageHeightIsDueWithBothHeights) {
    const Scene scene = loadScene(test::sourcePath("examples/vase/scene.json"));
    MultiphaseRenderer renderer(scene, everyFrame());
    FrameStats stats;
    renderer.renderFrame(0, tiny(), stats);
    RenderOptions taller = tiny();
    taller.height = 48;
    renderer.renderFrame(1, taller, stats);
    ASSERT_EQ(stats.staticRunsDue.size(), 2u);
    for (const StaticRunDue& d : stats.staticRunsDue) {
        EXPECT_EQ(d.cause, StaticRunDue::ImageSize);
        EXPECT_EQ(d.measured, 48.0f);
        EXPECT_EQ(d.threshold, 36.0f);
    }
}

}  // namespace
}  // namespace mpshade
