// frame_stats.h -- what one frame cost; written to stats.json by the CLI.
#pragma once

#include <cstdint>

namespace mpshade {

struct FrameStats {
    int index = 0;
    float time = 0.0f;         // scene time, seconds
    double wallSeconds = 0.0;  // whole frame, wall clock
    uint64_t samples = 0;      // sub-pixel samples
    uint64_t rays = 0;  // camera rays traced, continuation rays through translucency included
    uint64_t occlusionRays = 0;
    uint64_t shadedPoints = 0;        // shader invocations
    uint64_t shaderInstructions = 0;  // interpreter instructions executed, times lanes
    uint64_t nonFiniteSamples = 0;    // shader results that were NaN/Inf and were zeroed
};

}  // namespace mpshade
