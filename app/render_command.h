// render_command.h -- `mpshade render`: options and the command itself.
#pragma once

#include <cstdint>
#include <string>

#include "app/run_options.h"

namespace mpshade {

struct RenderCommandOptions {
    std::string scene;                // scene file
    std::string outDir;               // created if missing
    std::string mode = "multiphase";  // or "reference" (the judge)
    std::string frames;               // "A:B" half-open, or "N"; empty = every frame
    std::string size;                 // "WxH"; empty = the scene's
    int spp = -1;                     // -1 = the scene's; else 1..1024
    uint32_t seed = 0;
    bool quiet = false;       // no progress bar
    bool compare = false;     // multiphase: also render the reference, report error and speed
    std::string shadingRate;  // "sample" or "pixel"; empty = the scene's
    int truthSpp = -1;        // with compare: also measure both against this many spp
    int64_t memoryMb = 0;     // refuse renders estimated above this; 0: 3/4 of physical memory
    // Multiphase: probe footprint over the shading points' spacing (texel spacing of the
    // shader maps read); 0: the default (DynamicOptions::footprintScale); else 0.05..8.
    float footprintScale = 0.0f;
    // "measured" (each object's from its measured error, controller/footprint_calibration.h)
    // or "uniform" (every object's 1, times footprintScale).
    std::string footprints = "measured";
    // Multiphase: never render a frame single-phase, even where the static work it needs
    // would not pay for itself over the frames asked for (MultiphaseOptions).
    bool noSinglePhase = false;
    int viewLookahead = 24;  // frames ahead a static run may be built for; 0: the present view
    // Multiphase: the shader maps' tiles' memory budget, MB (MultiphaseOptions::
    // mapMemoryBytes); 0: its default.
    int64_t cacheMb = 0;
    RunOptions run;  // the shader-map store, threads
    // Frames whose EXR and PNG are both in the output folder already are not rendered again
    // (a farm task retried); their stats are not in this run's stats.json.
    bool skipExisting = false;
    // stats_A_B.json (this request's frames) instead of stats.json: shards rendering into one
    // folder each keep their own.
    bool shardStats = false;
    // "A:B": the frames the multi-phase renderer plans over, holding --frames; the frames
    // of it before the request are rendered first, not written, so each frame is the bits a
    // render of A:B gives, whichever request renders it (a farm's shards). Empty: --frames.
    std::string planFrames;
    // Multiphase: beside each frame, cost_NNNN.exr and .png -- per pixel, the shading points
    // the frame's dynamic phase made and their cost in opCost units (image_output.h); per
    // frame in stats.json, the cost per object. A frame rendered single-phase has none.
    bool costImages = false;
};

// Returns the exit code: 0, or 130 when stopped by Ctrl-C.
// Bad input throws InputError naming its place (the CLI prints it and exits 2); a file
// that cannot be written throws OutputError (exit 1).
int runRenderCommand(const RenderCommandOptions& options);

}  // namespace mpshade
