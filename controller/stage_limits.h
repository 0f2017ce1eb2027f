// stage_limits.h -- how far each stage of the dynamic phase is from the machine. A stage's
// cost is given in nanoseconds per sample per core (its wall time on the rendering thread,
// times the cores that share the work, over the frame's samples), beside the time the bytes
// it streams through memory would take at the machine's measured bandwidth: a lower bound
// for a stage that only streams (the rasterizer's visibility buffer, the resolve's samples
// and filter weights), and the part of a stage's time memory explains for one that computes
// (shading). Counted instructions are given where the stage counts them (the dynamic shader).
#pragma once

#include <string>
#include <vector>

#include "phases/frame_stats.h"

namespace mpshade {

struct StageCost {
    // "warp", "rasterize", "shade", its parts ("points", "interpolate", "probe", "kernel",
    // "composite" and "other": shade's time beyond them), "resolve", "dynamic phase"
    std::string name;
    bool part = false;              // a part of shade's time, not counted again in "dynamic phase"
    double nsPerSample = 0.0;       // per core, the median over the steady frames
    double bytesPerSample = 0.0;    // streamed through memory (read and written)
    double boundNsPerSample = 0.0;  // bytesPerSample at the measured bandwidth, per core
    double instructionsPerSample = 0.0;  // dynamic shader instructions (shade only), else 0
};

struct MachineLimits {
    int cores = 1;                // threads the work is spread over
    double bytesPerSecond = 0.0;  // memory bandwidth, all cores copying (read + write)
};

// Measures the memory bandwidth: every core copying its share of a 64 MiB buffer, best of
// three (about 0.1 s).
MachineLimits measureMachineLimits();

// The stages' costs over `frames` (rendered at `spp` samples per pixel): the steady ones
// (multi-phase, no static run), or every multi-phase frame but the first when none is
// steady. Empty when no frame was multi-phase. The bytes counted are the least a stage
// must move: one visibility layer a sample, the filter's weights for a reach of one pixel.
// Shade's parts are CPU time summed over the threads, per sample: what each part would
// cost a core; "other" is shade's figure less theirs (gathering pending points, waiting
// for the last band, scheduling). They carry no bytes; the kernel its instructions.
std::vector<StageCost> dynamicStageCosts(const std::vector<FrameStats>& frames, int spp,
                                         const MachineLimits& machine);

}  // namespace mpshade
