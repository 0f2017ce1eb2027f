// The cost profile: every frame's phases inside the frame, on the frame's own numbers, and
// each object's work where it was done.
#include <gtest/gtest.h>

#include "controller/cost_profile.h"
#include "scene/scene.h"
#include "test_support.h"

namespace mpshade {
namespace {

TEST(CostProfile, PhasesNestInTheirFramesAndObjectsCarryTheirOwnWork) {
    const Scene scene = loadScene(test::sourcePath("examples/vase/scene.json"));
    ProfileOptions options;
    options.render.width = 120;
    options.render.height = 68;
    options.first = 3;
    options.last = 6;
    std::vector<std::string> names;
    for (const SceneObject& o : scene.objects) names.push_back(o.name);
    TraceRecorder trace(names);
    const CostProfile p = profileScene(scene, "vase", options, trace);
    ASSERT_EQ(p.frames.size(), 3u);
    ASSERT_EQ(p.objects.size(), scene.objects.size());

    // Per frame: one frame span; the phase spans of that frame lie within it, and the
    // frame's static and shading spans add up to what its stats say.
    const std::vector<TraceRecorder::Span> spans = trace.spans();
    for (const FrameStats& s : p.frames) {
        const TraceRecorder::Span* frame = nullptr;
        double staticUs = 0.0, shadeUs = 0.0;
        int bands = 0;
        for (const TraceRecorder::Span& sp : spans) {
            if (sp.frame != s.index) continue;
            if (sp.kind == PhaseKind::Frame) {
                ASSERT_EQ(frame, nullptr) << "two frame spans for frame " << s.index;
                frame = &sp;
            }
            if (sp.level == SpanLevel::Phase && sp.kind == PhaseKind::Static)
                staticUs += sp.endUs - sp.beginUs;
            if (sp.level == SpanLevel::Phase && std::string(sp.name) == "shade")
                shadeUs += sp.endUs - sp.beginUs;
            bands += std::string(sp.name) == "band" ? 1 : 0;
        }
        ASSERT_NE(frame, nullptr) << s.index;
        for (const TraceRecorder::Span& sp : spans)
            if (sp.frame == s.index) {
                EXPECT_GE(sp.beginUs, frame->beginUs) << sp.name;
                EXPECT_LE(sp.endUs, frame->endUs) << sp.name;
            }
        EXPECT_NEAR(staticUs, 1e6 * s.staticWork.seconds,
                    0.02 * 1e6 * s.staticWork.seconds + 200.0);
        EXPECT_NEAR(shadeUs, 1e6 * s.dynamic.shadeSeconds,
                    0.02 * 1e6 * s.dynamic.shadeSeconds + 200.0);
        // Every band of 4 rows shaded at least once.
        EXPECT_GE(bands, (68 + 3) / 4);
    }
    // The first frame built both objects; later frames only filled.
    EXPECT_EQ(p.frames[0].staticWork.work.runs, 2);
    for (const ObjectProfile& o : p.objects) {
        SCOPED_TRACE(o.name);
        EXPECT_EQ(o.staticRuns, 1);
        EXPECT_EQ(o.framesDrawn, 3);
        // The vase's maps measure as binary16 (phases/map_precision.h), and say so.
        EXPECT_EQ(o.representation, "shadermap (half)");
        EXPECT_NE(o.reason.find("map precision half: rounding"), std::string::npos) << o.reason;
        EXPECT_GT(o.staticSecondsPerFrame[0], 0.0);
        EXPECT_GT(o.staticInstructions, 0u);  // its tiles' static shader runs
        EXPECT_GT(o.tilesFilled, 0u);
        EXPECT_GT(o.shadingPoints, 0u);
        EXPECT_GT(o.dynamicInstructions, o.shadingPoints);
        for (size_t k = 0; k < 3; ++k) {
            EXPECT_GT(o.shadeSecondsPerFrame[k], 0.0);
            // Summed over threads: at most every thread busy for the whole shading phase.
            EXPECT_LE(o.shadeSecondsPerFrame[k],
                      p.threads * p.frames[k].dynamic.shadeSeconds + 1e-4);
        }
    }
    // The points shaded are the frames' own.
    uint64_t points = 0, framePoints = 0;
    for (const ObjectProfile& o : p.objects) points += o.shadingPoints;
    for (const FrameStats& s : p.frames) framePoints += s.shadedPoints;
    EXPECT_EQ(points, framePoints);

    const std::string md = profileMarkdown(p);
    for (const SceneObject& o : scene.objects)
        EXPECT_NE(md.find("| " + o.name + " | shadermap (half) |"), std::string::npos) << md;
    EXPECT_NE(md.find("| 5 |"), std::string::npos);  // the last frame's row
}

}  // namespace
}  // namespace mpshade
