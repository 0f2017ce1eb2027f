// The dynamic stages per sample against the machine (stage_limits.h), from frame stats
// whose figures are worked out by hand: the steady frames chosen, nanoseconds per sample per
// core, the bytes each stage must stream and their time at a given bandwidth.
#include <gtest/gtest.h>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include "controller/stage_limits.h"
#include "phases/worker_threads.h"

namespace mpshade {
namespace {

FrameStats frame(double shadeSeconds, int staticRuns) {
    FrameStats f;
    f.samples = 1000000;
    f.dynamic.warpSeconds = 0.001;
    f.dynamic.rasterSeconds = 0.002;
    f.dynamic.shadeSeconds = shadeSeconds;
    f.dynamic.resolveSeconds = 0.004;
    f.dynamic.verticesWarped = 500000;
    f.dynamic.shadingPoints = 250000;
    f.dynamic.instructions = 30000000;
    f.staticWork.work.runs = staticRuns;
    // CPU seconds summed over two threads: 8 ms of parts against shade's 2 x 10 ms.
    f.dynamic.shadeParts = {0.001, 0.002, 0.003, 0.0015, 0.0005};
    return f;
}

TEST(StageLimits, SteadyFramesPerSamplePerCoreAgainstTheBandwidth) {
    // Two cores at 10 GB/s. The first frame ran the static phase and is left out; the
    // median of the steady frames' shading is 0.010 s: 20 ns a sample per core.
    const MachineLimits machine{2, 1e10};
    FrameStats single = frame(0.5, 0);
    single.singlePhase = true;
    const std::vector<FrameStats> frames = {frame(0.9, 3), frame(0.010, 0), frame(0.012, 0),
                                            frame(0.008, 0), single};
    const std::vector<StageCost> c = dynamicStageCosts(frames, 4, machine);
    ASSERT_EQ(c.size(), 11u);
    EXPECT_EQ(c[0].name, "warp");
    EXPECT_DOUBLE_EQ(c[0].nsPerSample, 2.0);      // 1 ms x 2 cores / 1e6 samples
    EXPECT_DOUBLE_EQ(c[0].bytesPerSample, 11.0);  // 22 bytes x 0.5 vertices a sample
    EXPECT_DOUBLE_EQ(c[1].nsPerSample, 4.0);
    EXPECT_DOUBLE_EQ(c[1].bytesPerSample, 21.0);
    EXPECT_DOUBLE_EQ(c[1].boundNsPerSample, 4.2);  // 21 bytes x 2 cores / 10 GB/s
    EXPECT_EQ(c[2].name, "shade");
    EXPECT_DOUBLE_EQ(c[2].nsPerSample, 20.0);
    EXPECT_DOUBLE_EQ(c[2].bytesPerSample, 29.0 + 80.0 * 0.25);
    EXPECT_DOUBLE_EQ(c[2].instructionsPerSample, 30.0);
    // Its parts, CPU seconds over the samples (not times the cores): 1, 2, 3, 1.5 and
    // 0.5 ns, and the 12 ns of shade's 20 they leave.
    const char* parts[] = {"points", "interpolate", "probe", "kernel", "composite", "other"};
    const double ns[] = {1.0, 2.0, 3.0, 1.5, 0.5, 12.0};
    for (int k = 0; k < 6; ++k) {
        EXPECT_EQ(c[3 + k].name, parts[k]);
        EXPECT_TRUE(c[3 + k].part);
        EXPECT_NEAR(c[3 + k].nsPerSample, ns[k], 1e-9) << parts[k];
        EXPECT_DOUBLE_EQ(c[3 + k].instructionsPerSample, k == 3 ? 30.0 : 0.0) << parts[k];
    }
    EXPECT_FALSE(c[2].part);
    EXPECT_EQ(c[9].name, "resolve");
    EXPECT_DOUBLE_EQ(c[9].nsPerSample, 8.0);
    EXPECT_DOUBLE_EQ(c[9].bytesPerSample, 40.0 + 20.0 / 4);
    EXPECT_EQ(c[10].name, "dynamic phase");
    EXPECT_DOUBLE_EQ(c[10].nsPerSample, 2.0 + 4.0 + 20.0 + 8.0);  // the parts not again
}

TEST(StageLimits, WithoutASteadyFrameEveryMultiphaseFrameButTheFirst) {
    const MachineLimits machine{1, 1e10};
    const std::vector<FrameStats> frames = {frame(0.9, 2), frame(0.002, 1), frame(0.004, 1)};
    const std::vector<StageCost> c = dynamicStageCosts(frames, 1, machine);
    ASSERT_EQ(c.size(), 11u);
    EXPECT_DOUBLE_EQ(c[2].nsPerSample, 3.0);  // the median of 2 and 4 ns
    FrameStats single = frame(0.5, 0);
    single.singlePhase = true;
    EXPECT_TRUE(dynamicStageCosts({single}, 1, machine).empty());
}

TEST(StageLimits, TheMeasuredBandwidthIsPlausible) {
    const MachineLimits m = measureMachineLimits();
    EXPECT_GE(m.cores, 1);
    EXPECT_GT(m.bytesPerSecond, 1e8);   // above 100 MB/s
    EXPECT_LT(m.bytesPerSecond, 1e13);  // below 10 TB/s
}

// Per-core figures multiply by the threads a frame could use: under a --threads 1 limit
// that is 1, whatever the arena's own concurrency says (counting every core had doubled
// one thread's figures on this 2-core machine).
TEST(StageLimits, CoresAreTheThreadsALimitLeaves) {
    {
        const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
        EXPECT_EQ(workerThreads(), 1);
        EXPECT_EQ(measureMachineLimits().cores, 1);
    }
    EXPECT_EQ(workerThreads(), tbb::this_task_arena::max_concurrency());
}

}  // namespace
}  // namespace mpshade
