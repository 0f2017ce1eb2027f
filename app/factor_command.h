// factor_command.h -- `mpshade factor`: how a shader splits into static and dynamic parts
// for one object's binding, for the shader's author.
#pragma once

#include <string>

namespace mpshade {

struct FactorCommandOptions {
    std::string shader;  // .sl file
    std::string scene;   // optional scene file
    std::string object;  // object in the scene whose binding to use (required with scene)
    bool json = false;   // machine-readable output
    bool dump = false;   // also print the IR of both parts
    // FactorOptions::storeAboveCost: a static part costing at most this is repeated by the
    // dynamic part rather than stored; -1: the engine's default; 0: always store.
    int storeAboveCost = -1;
};

// Returns the exit code: 0 success, 2 bad input (message already on stderr).
int runFactorCommand(const FactorCommandOptions& options);

}  // namespace mpshade
