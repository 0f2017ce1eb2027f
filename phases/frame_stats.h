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

    // Multi-phase rendering only (zero for the reference renderer).
    int staticRuns = 0;               // objects (re)processed by the static phase this frame
    double staticSeconds = 0.0;       // of wallSeconds, spent in the static phase
    double warpSeconds = 0.0;         // dynamic TSI: fixed-point warp
    double rasterSeconds = 0.0;       // dynamic TSI: binning and rasterization
    double shadeSeconds = 0.0;        // interpolation and the dynamic shader
    uint64_t staticInstructions = 0;  // static shader instructions, times lanes
    uint64_t facets = 0;              // facets of all objects' intermediate representations
    uint64_t facetsRasterized = 0;    // facet-tile pairs rasterized
    uint64_t fragments = 0;           // facet-sample hits
    uint64_t verticesWarped = 0;
    uint64_t facetBytes = 0;  // memory of the intermediate representations
};

}  // namespace mpshade
