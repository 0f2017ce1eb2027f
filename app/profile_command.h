// profile_command.h -- `mpshade profile`: what each phase costs, per object and per frame
// (controller/cost_profile.h), written as DIR/profile.md and DIR/trace.json.
#pragma once

#include <cstdint>
#include <string>

#include "app/run_options.h"

namespace mpshade {

struct ProfileCommandOptions {
    std::string scene;   // scene file
    std::string outDir;  // created if missing
    std::string frames;  // "A:B" half-open, or "N"; empty = every frame
    std::string size;    // "WxH"; empty = the scene's
    int spp = -1;        // -1 = the scene's; else 1..1024
    uint32_t seed = 0;
    bool quiet = false;  // no progress or summary on stderr
    RunOptions run;      // the shader-map store, threads
};

// Returns the exit code, 0.
// Bad input throws InputError naming its place (the CLI prints it and exits 2); a file
// that cannot be written throws OutputError (exit 1).
int runProfileCommand(const ProfileCommandOptions& options);

}  // namespace mpshade
