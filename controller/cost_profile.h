// cost_profile.h -- what each phase costs, per object and per frame: renders frames with
// the multi-phase renderer while a TraceRecorder keeps every span, and reports the static
// phase (building representations, filling tiles) against the dynamic phase (warp,
// rasterize, shade, resolve), as `mpshade profile` writes them (profile.md, trace.json).
//
// Times: a frame's phases are wall-clock seconds on the rendering thread; an object's
// static and shading seconds are summed over the threads that worked for it (its share of
// the parallel work, so they may add up to more than the wall clock).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "controller/multiphase_renderer.h"
#include "controller/stage_limits.h"
#include "controller/trace_recorder.h"

namespace mpshade {

struct ProfileOptions {
    RenderOptions render;     // image size, samples per pixel, seed (0: the scene's)
    int first = 0, last = 0;  // frames [first, last)
    // Its trace is the profile's recorder. Every frame multi-phase by default: a frame the
    // reference renders in its place has no phases to profile.
    MultiphaseOptions multiphase = everyFrameMultiphase();
    static MultiphaseOptions everyFrameMultiphase() {
        MultiphaseOptions o;
        o.singlePhaseFrames = false;
        return o;
    }
};

struct ObjectProfile {
    std::string name;
    // As stats.json names it, a shader map's precision after it: "shadermap (half)".
    std::string representation;
    std::string reason;  // why it was chosen
    int staticRuns = 0, framesDrawn = 0;
    double staticSeconds = 0.0;  // building and filling, summed over threads
    double shadeSeconds = 0.0;   // probing and shading its points, summed over threads
    uint64_t shadingPoints = 0;  // over every frame
    uint64_t staticInstructions = 0, dynamicInstructions = 0;
    uint64_t tilesFilled = 0, residentTiles = 0;
    uint64_t facets = 0;  // of its last representation
    uint64_t facetBytes = 0, mapBytes = 0;
    std::vector<double> staticSecondsPerFrame, shadeSecondsPerFrame;  // per profiled frame
    // The direct rule's last priced frame (static_run_triggers.h), CPU ms by the cost model:
    // the stored representation's work, and the reference's on the same samples (0: none).
    double pricedStoredMs = 0.0, pricedReferenceMs = 0.0;
};

struct CostProfile {
    std::string scene;
    int width = 0, height = 0, spp = 0, first = 0, last = 0;
    int threads = 0;                 // that reported spans
    bool singlePhaseFrames = false;  // the renderer could render frames single-phase
    double wallSeconds = 0.0;
    std::vector<FrameStats> frames;
    std::vector<ObjectProfile> objects;
    // The dynamic phase's stages per sample against the machine (stage_limits.h).
    MachineLimits machine;
    std::vector<StageCost> stages;
};

// Profiles frames [first, last) of `scene`; progress(frame) after each.
CostProfile profileScene(const Scene& scene, const std::string& scenePath,
                         const ProfileOptions& options, TraceRecorder& trace,
                         const std::function<void(int)>& progress = {});

// The representation of object `object` as reports name it: "none (never seen)",
// "geometry" (a static part not worth storing), "facets", "shadermap" or "direct".
std::string representationName(const MultiphaseRenderer& renderer, size_t object);
// "half" or "float": the precision of the object's shader map; empty without a map.
std::string mapPrecisionName(const MultiphaseRenderer& renderer, size_t object);

// profile.md: the run, static against dynamic, the dynamic stages against the machine, per
// object and per frame their costs.
std::string profileMarkdown(const CostProfile& profile);

}  // namespace mpshade
