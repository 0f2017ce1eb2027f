// play_command.h -- `mpshade play`: frame-rate-locked playback (controller/playback.h),
// frames written as `render` writes them (or not, with --no-write) and per frame in
// stats.json the time of each phase, whether it met its deadline, the quality it gave up
// and the work it left for later.
#pragma once

#include <cstdint>
#include <string>

#include "app/run_options.h"

namespace mpshade {

struct PlayCommandOptions {
    std::string scene;   // scene file
    std::string outDir;  // created if missing
    double fps = 30.0;   // 0.1 .. 1000
    std::string frames;  // "A:B" half-open, or "N"; empty = every frame
    std::string size;    // "WxH"; empty = the scene's
    int spp = -1;        // -1 = the scene's; else 1..1024
    uint32_t seed = 0;
    int64_t cacheMb = 256;              // shader-map tiles' memory budget, MB; >= 1
    bool noWrite = false;               // measure without the disk: stats.json only
    bool noPrefetch = false;            // no predicted or adjacent tiles filled ahead (comparisons)
    bool noBackgroundFills = false;     // no worker thread filling deferred tiles (comparisons)
    bool noBackgroundRebuilds = false;  // no worker thread rebuilding representations (same)
    std::string refine = "on";          // "on" or "off": refinement by image tile (tile_refiner.h)
    int refineTile = 16;                // refinement's tiles, pixels a side: even, 4..256
    std::string footprints = "measured";  // or "uniform": as render's --footprints
    // A folder of constant-quality frames (frame_NNNN.exr, as `render` writes them): each
    // played frame measured against its own there. Empty: none.
    std::string compareTo;
    bool quiet = false;
    RunOptions run;  // the shader-map store, threads
};

// Returns the exit code: 0, or 130 when stopped by Ctrl-C.
// Bad input throws InputError naming its place (the CLI prints it and exits 2); a file
// that cannot be written throws OutputError (exit 1).
int runPlayCommand(const PlayCommandOptions& options);

}  // namespace mpshade
