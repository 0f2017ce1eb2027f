// factor_command.h -- `mpshade factor`: how a shader splits into static and dynamic parts
// for one object's binding, for the shader's author.
#pragma once

#include <string>
#include <vector>

#include "shading/binding_time.h"

namespace mpshade {

// Three forms: a shader file alone (parameters at their defaults, a fixed ambient and
// distant light); --scene with --object (the object's binding and, without a shader file,
// its shader; a shader file that is not the object's is factored on its binding, with a
// note); --scene alone (every object, each with its own shader and binding).
struct FactorCommandOptions {
    std::string shader;  // .sl file; optional with --scene
    std::string scene;   // optional scene file
    std::string object;  // object in the scene whose binding to use
    bool json = false;   // machine-readable output
    bool dump = false;   // also print the IR of both parts
    // FactorOptions::storeAboveCost: stored values whose static work costs at most this
    // (opCost units a point) are repeated by the dynamic part instead; 0: store them all.
    int storeAboveCost = FactorOptions{}.storeAboveCost;
    // With --scene: evaluate the split against the whole shader (split_verification.h);
    // the command exits 1 when the largest relative difference is over `tolerance`.
    bool verify = false;
    double tolerance = 1e-5;
    // What-ifs: expressions (line:column, or a variable's name) to store or to repeat every
    // frame, on top of the binding's own; the report then compares with the split without.
    std::vector<std::string> store, repeat;
};

// Returns the exit code: 0 success; 1 when --verify found a difference over --tolerance.
// Bad input throws InputError naming its place (the CLI prints it and exits 2); a file
// that cannot be written throws OutputError (exit 1).
int runFactorCommand(const FactorCommandOptions& options);

}  // namespace mpshade
