// eval_runner.h -- one configuration of `mpshade eval` (docs/evaluation.md): a renderer and
// its knobs, timed over a run of frames and measured frame by frame against the truth.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "phases/dynamic_phase.h"
#include "phases/image.h"
#include "phases/reference_renderer.h"
#include "scene/scene.h"
#include "shadermaps/probe.h"

namespace mpshade {

// Every knob that trades speed for error. Defaults are the engine's own (a run with every
// default is what `mpshade render` does).
struct EvalConfig {
    bool multiphase = true;
    std::string knob = "default";  // the knob this rung of the ladder moves ("spp", ...)
    std::string label;             // short, unique within a scene: "mp spp=2"
    int spp = 0;                   // 0: the scene's
    // Multi-phase only:
    ShadingRate shadingRate = ShadingRate::Sample;
    // The map resolution bias: larger reads coarser levels.
    float footprintScale = DynamicOptions{}.footprintScale;
    ProbeFilter filter = DynamicOptions{}.probe.filter;
    float maxAnisotropy = DynamicOptions{}.probe.maxAnisotropy;
    float levelAnisotropy = DynamicOptions{}.probe.levelAnisotropy;
    float facetEdgePixels = 0.5f;   // combined representation: the facet size target
    float rangeScale = 1.0f;        // scales every object's range (distance factor - 1, angle)
    int cacheMb = 96;               // the shader maps' tile budget
    bool cutEveryFrame = false;     // every frame starts with no static work to reuse
    bool singlePhaseFrames = true;  // frames whose static work would not pay go single-phase
    // A shader-map store folder the run reads and adds to (docs/store.md); empty: none, every
    // tile filled (the ladders' runs, so each pays its static work).
    std::string storeFolder;
};

struct EvalFrame {
    int index = 0;
    double wallSeconds = 0.0;    // the whole frame, static work included
    double staticSeconds = 0.0;  // of which static (dicing, tile fills)
    double mse = 0.0, psnr = 0.0, rmse = 0.0, maxAbs = 0.0;
    double temporalRmse = -1.0;  // against the previous frame; -1 for the first
    uint64_t nonFinite = 0;
    bool singlePhase = false;  // multi-phase chose to render this frame single-phase
};

struct EvalRun {
    EvalConfig config;
    std::vector<EvalFrame> frames;
    double setupSeconds = 0.0;            // building the renderer (ray scenes, shaders)
    double sequenceSeconds = 0.0;         // setup and every frame
    double staticSeconds = 0.0;           // every static phase and fill
    double dynamicSecondsPerFrame = 0.0;  // mean of wall - static
    double steadyFrameSeconds = 0.0;      // median wall time of the frames after the first
    double peakMemoryMb = 0.0;            // resident memory the run added at its peak (-1: unknown)
    // Over the whole sequence: PSNR of the mean squared error, RMSE, the largest error of a
    // channel, the mean temporal error.
    double psnr = 0.0, rmse = 0.0, maxAbs = 0.0, temporalRmse = 0.0;
    uint64_t nonFinite = 0;
    int singlePhaseFrames = 0;
};

// Renders frames [first, last) of the scene at `scenePath` with `config`, comparing frame i
// with truth[i - first]. `base` gives size and seed. Calls `frameDone` after each frame.
EvalRun runEvalConfig(const std::string& scenePath, const EvalConfig& config, int first, int last,
                      const RenderOptions& base, const std::vector<Image>& truth,
                      const std::function<void()>& frameDone = {});

// The resident memory of this process now and the peak since the last reset, in bytes (0 if
// unknown); resetPeakResident() lowers the peak to the current size (Linux clear_refs),
// returning false where it cannot.
uint64_t currentResidentBytes();
uint64_t peakResidentSinceReset();
bool resetPeakResident();

}  // namespace mpshade
