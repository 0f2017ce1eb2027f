// factoring.h -- the factoring front end: a shader, specialized to one object's binding,
// split into a static part (surface point -> n-tuple) and a dynamic part (n-tuple + frame
// instance -> Ci, Oi), so that S(A, I) = S_d(S_s(A, R), I) (patent US 6,359,619, col. 6).
//
// 1. Lower the shader for the binding (constants fold; shading/lower.h).
// 2. Binding-time analysis (binding_time.h).
// 3. Reassociate sums and products so static terms group (reassociate.h); analyse again.
// 4. Choose the n-tuple as a minimum vertex cut between the static work and the dynamic
//    consumers (min_cut.h): every stored value costs one float; expensive static work
//    (noise, lighting, occlusion, baked values) must be on the static side; cheap static
//    arithmetic may be repeated by the dynamic part. Among minimum cuts, the one closest
//    to the dynamic consumers, so the dynamic part repeats as little as possible.
// 5. The static part computes the cut values; the dynamic part reads them as channels.
#pragma once

#include <string>
#include <vector>

#include "shading/ast.h"
#include "shading/binding.h"
#include "shading/binding_time.h"
#include "shading/ir.h"

namespace mpshade {

// One float of the n-tuple.
struct ChannelInfo {
    std::string name;  // the variable it came from ("Cd[0]"), or "" for a temporary
    ValueType type = ValueType::Float;  // of the source value this is a component of
    int component = -1;                 // 0..2 within that value, -1 for a scalar
    int line = 0, column = 0;           // the source expression that computes it
    Op op = Op::Const;                  // the operation that computes it
};

// One input that makes a line dynamic (or that a bake() freezes).
struct DynamicCause {
    // "view" (I or E), "time", "parameter" (name: the parameter), "ambient_light" and
    // "light" (index: the scene light), "annotation" (a dynamic() in the source),
    // "override" (the binding's repeat of it: scene "factoring", or factor --repeat).
    std::string kind;
    std::string name;
    int index = -1;
    std::string why;           // for a reader: "parameter 'k' is animated"
    int line = 0, column = 0;  // where the input enters the shader
};

// A dynamic source line and why it is dynamic: the chain from a dynamic input to it, and
// every input that reaches it.
struct DynamicLine {
    int line = 0;
    std::vector<std::string> chain;  // from the line's first dynamic operation back to the input
    std::vector<DynamicCause> causes;
};

// What a source line's work is for this binding (a line may do several kinds).
struct SourceLineStages {
    int line = 0;
    bool repeated = false;  // dynamic: run every frame
    bool stored = false;    // static: the static phase's (stored, or repeated if cheaper)
    bool baked = false;     // static under a bake() that freezes a dynamic input
    bool free = false;      // cheap arithmetic on geometry the frames have anyway
};

struct FactoredShader {
    IrProgram analyzed;     // the lowered, reassociated program the cut was made in
    BindingTimes times;     // of `analyzed`
    IrProgram staticPart;   // writes channelOutputs, one per channel
    IrProgram dynamicPart;  // reads channelInputs channels, writes Ci and Oi
    std::vector<ChannelInfo> channels;
    int naiveWidth = 0;   // floats if every static value a dynamic operation reads were stored
    int chosenWidth = 0;  // floats stored: channels.size()
    // Per-sample cost, in instructions (constants excluded) and in opCost units.
    int originalInstructions = 0, staticInstructions = 0, dynamicInstructions = 0;
    int originalCost = 0, staticCost = 0, dynamicCost = 0;
    // The static work left to the dynamic part because storing it would cost more than
    // repeating it (FactorOptions::storeAboveCost); 0 when the cut's values are all stored.
    int recomputedStaticCost = 0;
    std::vector<DynamicLine> dynamicLines;
    // Lines whose bake() freezes a dynamic input (its chain ends at the input): computed once
    // by the static phase at its representative time, view, parameters and lights.
    std::vector<DynamicLine> bakedLines;
    std::vector<SourceLineStages> lineStages;  // per source line with work, in order
    // Annotations that do nothing for this binding, each "line:col: what" (a bake() of a
    // value already static, a dynamic() of a constant).
    std::vector<std::string> warnings;
};

FactoredShader factorShader(const ShaderAst& ast, const ShaderBinding& binding,
                            const FactorOptions& options = {});

// Instructions other than constants, and their summed opCost.
int instructionCount(const IrProgram& program);
int programCost(const IrProgram& program);

}  // namespace mpshade
