// ir.h -- the shader IR: a straight-line SSA program over scalar float values.
//
// Why this shape: loops are unrolled (their bounds are constant after folding) and `if`
// becomes a per-component Select, so a shader is a DAG of scalar operations. A DAG makes
// binding-time analysis a single forward pass and the static/dynamic cut a graph cut, and
// it runs on the batched interpreter with no divergence. 3-component values are three
// scalar values; ints are floats holding whole numbers (exact up to 2^24).
//
// Every value is defined once. Instruction k defines values result .. result + nout - 1
// and reads args[firstArg .. firstArg + nargs - 1]. Instructions are in dependency order.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "shading/builtins.h"

namespace mpshade {

enum class Op : uint8_t {
    // Sources (no args)
    Const,         // constant
    Global,        // imm = GlobalId; nout = components
    Param,         // imm = animated parameter slot; nout = components
    LightAmbient,  // imm = light index; nout = 3 (an animated ambient light's color)
    Channel,       // imm = n-tuple channel; the dynamic part of a factored shader reads it
    // Unary
    Neg,
    Abs,
    Floor,
    Ceil,
    Fract,
    Sqrt,
    Exp,
    Log,
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Sign,
    Trunc,
    Not,
    Bake,
    Dynamic,  // identity; marks a factoring override
    // Binary
    Add,
    Sub,
    Mul,
    Div,
    IDiv,
    Min,
    Max,
    Mod,
    Pow,
    Atan2,
    Step,
    Lt,
    Le,
    Gt,
    Ge,
    Eq,
    Ne,
    And,
    Or,
    // Ternary
    Clamp,
    Mix,
    Smoothstep,
    Select,  // Select(cond, a, b) = cond != 0 ? a : b
    // Pattern: args x, y, z; imm = octaves (Fbm, Turbulence)
    Noise,
    Snoise,
    Cellnoise,
    Fbm,
    Turbulence,
    // Lighting by one light: imm = light index; nout = 3.
    Diffuse,   // args P(3) N(3)
    Specular,  // args P(3) N(3) V(3) roughness
    Phong,     // args P(3) N(3) V(3) exponent
    // Visibility: args P(3) N(3); imm = ray count
    Occlusion,
    Count
};

const char* opName(Op op);
// True for operations whose result depends only on their arguments (foldable, CSE-able).
bool isPureArithmetic(Op op);

struct Inst {
    Op op;
    uint8_t nargs = 0;
    uint8_t nout = 1;
    int32_t imm = 0;
    float constant = 0.0f;
    int32_t firstArg = 0;
    int32_t result = 0;
    int32_t line = 0, column = 0;  // the source expression this came from
};

// What the source called a value, for reports: "Cd[1]", or a temporary's type and
// component. Filled by lowering; kept through dead-code elimination.
struct ValueInfo {
    std::string name;  // variable name with component ("Cd[1]"); empty for temporaries
    ValueType type = ValueType::Float;
    int8_t component = -1;  // 0..2 in a 3-component value; -1 for a scalar
};

struct AnimatedParam {
    std::string name;
    int slot;        // first float of the parameter in the per-frame parameter block
    int components;  // 1 or 3
};

struct IrProgram {
    std::string shaderName;
    std::string file;
    std::vector<Inst> insts;
    std::vector<int32_t> args;
    int valueCount = 0;
    // Outputs. A shader's program writes Ci and Oi; the static part of a factored shader
    // writes the n-tuple channels instead (ci and oi stay -1).
    int ci[3] = {-1, -1, -1};
    int oi[3] = {-1, -1, -1};
    std::vector<int32_t> channelOutputs;
    int channelInputs = 0;        // n-tuple channels read by Channel instructions
    std::vector<ValueInfo> info;  // per value (may be empty)
    std::string source;           // the shader's text, for reports (may be empty)
    std::vector<AnimatedParam> animatedParams;
    int paramFloats = 0;  // size of the per-frame parameter block

    const int32_t* argsOf(const Inst& i) const { return args.data() + i.firstArg; }
    // The same shader's names, parameters and source, with no instructions or outputs.
    IrProgram emptyCopy() const;
    // Prints one instruction per line ("%12 = mul %3 %7   ; line 9"), for tests and --dump.
    std::string dump() const;
};

// For each value, the index of the instruction that defines it.
std::vector<int> definingInstructions(const IrProgram& program);

// Removes instructions no output (Ci, Oi, channel outputs) depends on and renumbers
// values densely.
void eliminateDeadCode(IrProgram& program);

}  // namespace mpshade
