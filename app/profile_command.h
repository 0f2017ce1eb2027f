// profile_command.h -- `mpshade profile`: what each phase costs, per object and per frame
// (controller/cost_profile.h), written as DIR/profile.md and DIR/trace.json.
#pragma once

#include <cstdint>
#include <string>

namespace mpshade {

struct ProfileCommandOptions {
    std::string scene;   // scene file
    std::string outDir;  // created if missing
    std::string frames;  // "A:B" half-open, or "N"; empty = every frame
    std::string size;    // "WxH"; empty = the scene's
    int spp = -1;        // -1 = the scene's; else 1..1024
    uint32_t seed = 0;
    bool quiet = false;  // no progress or summary on stderr
};

// Returns the process exit code: 0 success, 1 output failure, 2 bad input (message on stderr).
int runProfileCommand(const ProfileCommandOptions& options);

}  // namespace mpshade
