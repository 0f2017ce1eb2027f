// When an object goes back through the static phase, and why: the fiducial that crossed
// its threshold, measured here independently from the scene's camera.
#include <cmath>
#include <fstream>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "controller/multiphase_renderer.h"
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
    ASSERT_EQ(stats.staticWork.due.size(), 2u);
    for (const StaticRunDue& d : stats.staticWork.due) {
        EXPECT_EQ(d.cause, StaticRunDue::FirstSeen);
        EXPECT_FALSE(d.deferred);
    }
    for (int frame = 1; frame <= 5; ++frame) {
        renderer.renderFrame(frame, tiny(), stats);
        EXPECT_EQ(stats.staticWork.work.runs, 0) << frame;
        EXPECT_TRUE(stats.staticWork.due.empty()) << frame;
    }
}

TEST(RerunTriggers, LeavingTheRangeRunsExactlyTheObjectsThatLeftItAndSaysWhy) {
    const Scene scene = loadScene(test::sourcePath("examples/vase/scene.json"));
    MultiphaseOptions o = everyFrame();
    o.viewLookahead = 0;  // built for the present view: the range is frame 0's
    MultiphaseRenderer renderer(scene, o);
    FrameStats stats;
    const int floorIndex = scene.objects[0].name == "floor" ? 0 : 1;
    for (int frame = 0; frame <= 6; ++frame) renderer.renderFrame(frame, tiny(), stats);
    // Frame 6: the floor's view direction has turned past 10 degrees from frame 0's; the
    // vase, 30 degrees, stays.
    ASSERT_EQ(stats.staticWork.due.size(), 1u);
    const StaticRunDue& d = stats.staticWork.due[0];
    EXPECT_EQ(d.object, static_cast<uint32_t>(floorIndex));
    EXPECT_EQ(d.cause, StaticRunDue::ViewDirection);
    EXPECT_EQ(d.threshold, 10.0f);
    EXPECT_EQ(stats.staticWork.work.runs, 1);
    const glm::vec3 f0 = cameraAt(scene, scene.frameTime(0), 64, 36).forward;
    const glm::vec3 f6 = cameraAt(scene, scene.frameTime(6), 64, 36).forward;
    const float turned = glm::degrees(std::acos(glm::dot(f0, f6)));
    EXPECT_GT(turned, 10.0f);
    EXPECT_NEAR(d.measured, turned, 0.05f);
    // The floor was re-run at frame 6: frame 7 is in its new range.
    renderer.renderFrame(7, tiny(), stats);
    EXPECT_TRUE(stats.staticWork.due.empty());
}

// With the camera's path known, the floor is built for a view ahead whose range holds the
// present one: it is built less often over the orbit, and every frame drawn from a
// representation is inside that representation's range.
TEST(RerunTriggers, BuildingForAViewAheadRunsTheStaticPhaseLessOften) {
    const Scene scene = loadScene(test::sourcePath("examples/vase/scene.json"));
    const int floorIndex = scene.objects[0].name == "floor" ? 0 : 1;
    auto floorRuns = [&](int lookahead) {
        MultiphaseOptions o = everyFrame();
        o.viewLookahead = lookahead;
        MultiphaseRenderer renderer(scene, o);
        FrameStats stats;
        for (int frame = 0; frame < 24; ++frame) {
            renderer.renderFrame(frame, tiny(), stats);
            const ObjectRepresentation* rep = renderer.representation(floorIndex);
            const CameraState camera = cameraAt(scene, scene.frameTime(frame), 64, 36);
            const ObjectState state =
                objectAt(scene.objects[floorIndex], scene.frameTime(frame), camera);
            const glm::vec3 forward =
                glm::normalize(glm::vec3(state.worldToObject * glm::vec4(camera.forward, 0.0f)));
            EXPECT_TRUE(rep->inRange(state.eye, forward)) << lookahead << " " << frame;
            if (frame == 0 && lookahead > 0) {
                EXPECT_NE(rep->representativeEye, state.eye);
            }
        }
        return renderer.slot(floorIndex).report.staticCosts.runs;
    };
    const int present = floorRuns(0), ahead = floorRuns(8);
    // 1.875 degrees a frame against a 10-degree range: a range about the present view holds
    // 6 frames (0-5), one about the view 5 frames ahead 11 (0-10).
    EXPECT_EQ(present, 4);
    EXPECT_EQ(ahead, 3);
}

TEST(RerunTriggers, ANewImageHeightIsDueWithBothHeights) {
    const Scene scene = loadScene(test::sourcePath("examples/vase/scene.json"));
    MultiphaseRenderer renderer(scene, everyFrame());
    FrameStats stats;
    renderer.renderFrame(0, tiny(), stats);
    RenderOptions taller = tiny();
    taller.height = 48;
    renderer.renderFrame(1, taller, stats);
    ASSERT_EQ(stats.staticWork.due.size(), 2u);
    for (const StaticRunDue& d : stats.staticWork.due) {
        EXPECT_EQ(d.cause, StaticRunDue::ImageSize);
        EXPECT_EQ(d.measured, 48.0f);
        EXPECT_EQ(d.threshold, 36.0f);
    }
}

}  // namespace
}  // namespace mpshade

namespace mpshade {
namespace {

// A ball whose baked colour follows an animated parameter (k: 0 at t = 0 to 1 at t = 1),
// and one whose animated parameter stays dynamic (not baked); the camera stands still.
std::string writeBakedInputScene() {
    const std::string dir = test::testFolder("mpshade_rerun");
    {
        std::ofstream sl(dir + "mpshade_baked_k.sl");
        sl << "surface baked_k(float k = 0.0) {\n"
              "    Ci = bake(color(k) * (0.5 + 0.5 * noise(P * 3.0)));\n"
              "    Oi = 1.0;\n"
              "}\n";
        std::ofstream dyn(dir + "mpshade_dynamic_k.sl");
        dyn << "surface dynamic_k(float k = 0.0) {\n"
               "    Ci = color(k) * (0.5 + 0.5 * noise(P * 3.0));\n"
               "    Oi = 1.0;\n"
               "}\n";
    }
    const std::string path = dir + "mpshade_baked_input_scene.json";
    std::ofstream f(path);
    f << R"({
  "settings": {"width": 64, "height": 36, "fps": 10, "duration": 1.0, "samples_per_pixel": 1},
  "camera": {"fov_y": 40, "near": 0.1, "far": 100, "keys": [
    {"t": 0, "eye": [0, 0, 6], "target": [0, 0, 0]}]},
  "shaders": {"baked": ")"
      << dir << R"(mpshade_baked_k.sl", "dynamic": ")" << dir << R"(mpshade_dynamic_k.sl"},
  "objects": [
    {"name": "baked", "geometry": {"type": "sphere", "radius": 1.0}, "shader": "baked",
     "transform": {"translate": [-1.2, 0, 0]},
     "params": {"k": {"keys": [{"t": 0, "value": 0.0}, {"t": 1, "value": 1.0}]}}},
    {"name": "dynamic", "geometry": {"type": "sphere", "radius": 1.0}, "shader": "dynamic",
     "transform": {"translate": [1.2, 0, 0]},
     "params": {"k": {"keys": [{"t": 0, "value": 0.0}, {"t": 1, "value": 1.0}]}}}]
})";
    return path;
}

double meanRed(const Image& image, int x0, int x1) {
    double sum = 0.0;
    for (int y = 0; y < image.height; ++y)
        for (int x = x0; x < x1; ++x)
            sum += image.rgba[4 * (static_cast<size_t>(y) * image.width + x)];
    return sum / ((x1 - x0) * image.height);
}

TEST(RerunTriggers, ABakedAnimatedInputThatMovesRunsTheStaticPhaseAgain) {
    const Scene scene = loadScene(writeBakedInputScene());
    ASSERT_EQ(scene.frameCount(), 10);
    MultiphaseRenderer renderer(scene, everyFrame());
    FrameStats stats;
    renderer.renderFrame(0, tiny(), stats);
    ASSERT_EQ(stats.staticWork.due.size(), 2u);  // both first seen
    renderer.renderFrame(1, tiny(), stats);
    // k moved 0.1 of its span over the frames (t = 0 .. 0.9: 0.9): 0.111 > 0.02.
    ASSERT_EQ(stats.staticWork.due.size(), 1u);
    const StaticRunDue& d = stats.staticWork.due[0];
    EXPECT_EQ(d.object, 0u);
    EXPECT_EQ(d.cause, StaticRunDue::StaticInput);
    EXPECT_NEAR(d.measured, 0.1f / 0.9f, 1e-4f);
    EXPECT_EQ(d.threshold, 0.02f);
    EXPECT_EQ(stats.staticWork.work.runs, 1);
    // The baked ball follows k: at frame 7 it is as bright as the reference renderer's.
    const Image image = renderer.renderFrame(7, tiny(), stats);
    ReferenceRenderer reference(scene);
    FrameStats refStats;
    const Image truth = reference.renderFrame(7, tiny(), refStats);
    const double got = meanRed(image, 0, 32), want = meanRed(truth, 0, 32);
    ASSERT_GT(want, 0.05);
    EXPECT_NEAR(got / want, 1.0, 0.02);
}

TEST(RerunTriggers, AnInputMovingWithinTheToleranceRunsNothing) {
    const Scene scene = loadScene(writeBakedInputScene());
    MultiphaseOptions o = everyFrame();
    o.staticInputTolerance = 0.5f;  // half of k's span: 4.5 frames
    MultiphaseRenderer renderer(scene, o);
    FrameStats stats;
    for (int frame = 0; frame <= 4; ++frame) {
        renderer.renderFrame(frame, tiny(), stats);
        if (frame > 0) {
            EXPECT_TRUE(stats.staticWork.due.empty()) << frame;
        }
    }
    renderer.renderFrame(5, tiny(), stats);  // 0.5 / 0.9 = 0.56 of the span
    ASSERT_EQ(stats.staticWork.due.size(), 1u);
    EXPECT_EQ(stats.staticWork.due[0].cause, StaticRunDue::StaticInput);
    EXPECT_NEAR(stats.staticWork.due[0].measured, 0.5f / 0.9f, 1e-4f);
}

}  // namespace
}  // namespace mpshade

namespace mpshade {
namespace {

// Two balls far apart; the camera looks at the first, cuts to the second at t = 1 and
// back to the first view at t = 2.
std::string writeCutScene() {
    const std::string path = ::testing::TempDir() + "mpshade_cut_scene.json";
    std::ofstream f(path);
    f << R"({
  "settings": {"width": 64, "height": 36, "fps": 10, "duration": 3.0, "samples_per_pixel": 1},
  "camera": {"fov_y": 30, "near": 0.1, "far": 100, "keys": [
    {"t": 0, "eye": [0, 0, 6], "target": [0, 0, 0]},
    {"t": 0.99, "eye": [0, 0, 6], "target": [0, 0, 0]},
    {"t": 1.0, "eye": [20, 0, 6], "target": [20, 0, 0]},
    {"t": 1.99, "eye": [20, 0, 6], "target": [20, 0, 0]},
    {"t": 2.0, "eye": [0, 0, 6], "target": [0, 0, 0]}]},
  "lights": [{"type": "distant", "direction": [0, -1, -1], "color": [1, 1, 1]}],
  "shaders": {"marble": ")"
      << test::sourcePath("examples/shaders/marble.sl") << R"("},
  "objects": [
    {"name": "first", "geometry": {"type": "sphere", "radius": 1.0}, "shader": "marble"},
    {"name": "second", "geometry": {"type": "sphere", "radius": 1.0}, "shader": "marble",
     "transform": {"translate": [20, 0, 0]}}]
})";
    return path;
}

TEST(RerunTriggers, ACameraCutRunsOnlyWhatTheNewViewNeeds) {
    const Scene scene = loadScene(writeCutScene());
    MultiphaseRenderer renderer(scene, everyFrame());
    FrameStats stats;
    renderer.renderFrame(0, tiny(), stats);
    ASSERT_EQ(stats.staticWork.due.size(), 1u);
    EXPECT_EQ(stats.staticWork.due[0].object, 0u);  // the second ball is not seen: not built
    EXPECT_EQ(renderer.representation(1), nullptr);
    for (int frame = 1; frame < 10; ++frame) {
        renderer.renderFrame(frame, tiny(), stats);
        EXPECT_TRUE(stats.staticWork.due.empty()) << frame;
    }
    renderer.renderFrame(10, tiny(), stats);  // the cut: only the second ball, first seen
    ASSERT_EQ(stats.staticWork.due.size(), 1u);
    EXPECT_EQ(stats.staticWork.due[0].object, 1u);
    EXPECT_EQ(stats.staticWork.due[0].cause, StaticRunDue::FirstSeen);
    EXPECT_EQ(stats.staticWork.work.runs, 1);
    for (int frame = 11; frame < 20; ++frame) {
        renderer.renderFrame(frame, tiny(), stats);
        EXPECT_TRUE(stats.staticWork.due.empty()) << frame;
    }
    // Back to the first view: the first ball's representation still holds for it.
    renderer.renderFrame(20, tiny(), stats);
    EXPECT_TRUE(stats.staticWork.due.empty());
    EXPECT_EQ(stats.staticWork.work.runs, 0);
    EXPECT_EQ(stats.objectsDrawn, 1u);
}

}  // namespace
}  // namespace mpshade
