// lower.h -- turns a type-checked shader and its binding into IR (ir.h): loops unrolled,
// `if` turned into selects, parameters bound, lighting split per light, constants folded,
// dead code removed.
#pragma once

#include "shading/ast.h"
#include "shading/binding.h"
#include "shading/ir.h"
#include "shading/ir_builder.h"

namespace mpshade {

struct LoweringLimits {
    int maxLoopIterations = 4096;     // per loop statement
    int maxInstructions = 1'000'000;  // after unrolling
};

// Throws InputError (file:line:col) for what only lowering can see: non-constant loop
// bounds, octave or sample counts, or component indices; too many iterations.
IrProgram lowerShader(const ShaderAst& ast, const ShaderBinding& binding,
                      const LoweringLimits& limits = {}, FoldStats* stats = nullptr);

}  // namespace mpshade
