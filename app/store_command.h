// store_command.h -- `mpshade bake` (fill the shader-map store with what frames need) and
// `mpshade store info|gc|export` (what a store holds, clean-up, maps as images); see
// docs/store.md.
#pragma once

#include <cstdint>
#include <string>

#include "app/run_options.h"

namespace mpshade {

struct BakeCommandOptions {
    std::string scene;   // scene file
    std::string frames;  // "A:B" half-open, or "N"; empty = every frame
    std::string size;    // "WxH"; empty = the scene's
    int spp = -1;        // -1 = the scene's
    uint32_t seed = 0;
    bool quiet = false;
    RunOptions run;  // the store (required: --no-store is refused), threads
};

// Renders the frames multi-phase, writing no image, so that every tile they read is filled
// and written to the store; reports per object the tiles found there and filled. Returns 0.
int runBakeCommand(const BakeCommandOptions& options);

struct StoreCommandOptions {
    std::string action;  // "info", "gc" or "export"
    std::string store;   // empty: the default folder
    bool json = false;   // info: machine-readable
    int64_t maxMb = -1;  // gc: the budget, MB (required)
    // export: the scene and object whose maps are written, and where.
    std::string scene, object, outDir;
    int maxSize = 1024;  // export: the finest level written is at most this wide
};

int runStoreCommand(const StoreCommandOptions& options);

}  // namespace mpshade
