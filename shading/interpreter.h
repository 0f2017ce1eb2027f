// interpreter.h -- runs an IR program over a batch of shading points, structure of arrays.
//
// The program is first compiled to a ShaderKernel: values get registers by linear scan
// (a register is reused once its value is dead), constants get registers of their own
// filled once. Running it dispatches once per instruction per chunk of kLanes points and
// then loops over the lanes, so the per-sample cost is a tight loop the compiler can
// vectorize: no virtual calls, name lookups or allocation per sample.
#pragma once

#include <atomic>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "shading/binding.h"
#include "shading/ir.h"
#include "shading/stop_signal.h"

namespace mpshade {

class SurfaceRayScene;

// One light as the shader sees it this frame, in the shaded object's own coordinates.
struct LightSample {
    LightKind kind = LightKind::Distant;
    glm::vec3 color{0.0f};                // color * intensity (point lights: at unit distance)
    glm::vec3 position{0.0f};             // Point
    glm::vec3 toLight{0.0f, 1.0f, 0.0f};  // Distant: unit direction towards the light
};

// What a light's result goes on to, done in the light's own pass over the lanes (the kernel
// is bound by its passes through L1): channel c is written as base[c] + scale[c] * light, or
// base[c] + light where scale[c] is null, each product and sum rounded as the shader's own
// instructions round them (no fused multiply-add), so the same bits as those instructions
// after the light (but for a NaN's payload). Rows of m lanes, read at the light's lanes.
struct LightEpilogue {
    const float* scale[3] = {};
    const float* base[3] = {};
};

// Per object, per frame.
struct ShadingUniforms {
    float time = 0.0f;
    glm::vec3 eye{0.0f};                  // E, object space
    std::span<const float> params;        // the animated parameter block (IrProgram::paramFloats)
    std::span<const LightSample> lights;  // indexed as the binding's lights
    const SurfaceRayScene* occluder = nullptr;  // the object's own geometry; null: no occlusion
    float occlusionBias = 1e-4f;                // ray origin offset along N, object units
};

// Per point, structure of arrays; each pointer addresses n floats. Object space.
struct ShadingInputs {
    const float* P[3] = {};
    const float* N[3] = {};
    const float* Ng[3] = {};
    const float* dPdu[3] = {};
    const float* dPdv[3] = {};
    const float* I[3] = {};
    const float* u = nullptr;
    const float* v = nullptr;
    const float* s = nullptr;
    const float* t = nullptr;
    // The n-tuple, for the dynamic part of a factored shader: channels[k] has n floats.
    const float* const* channels = nullptr;
};

// Where results go. A program writes the outputs it has: Ci and Oi, or, for the static
// part of a factored shader, the n-tuple channels (channels[k] receives n floats).
struct ShadingOutputs {
    float* Ci[3] = {};
    float* Oi[3] = {};
    float* const* channels = nullptr;
};

struct ShadingCounters {
    uint64_t instructions = 0;  // instructions executed, times lanes
    uint64_t points = 0;
    uint64_t occlusionRays = 0;
};

// A multiplication fused into the addition or subtraction that is its only reader: one
// pass over the lanes for the two (the kernel is bound by its passes through L1), each
// lane rounding the product and then the sum as the two instructions did. With op Mul,
// in[0] * in[1] is t and in[2] the other operand.
enum class MulFusion : uint8_t {
    None,
    ProductPlus,   // t + in[2]
    PlusProduct,   // in[2] + t
    ProductMinus,  // t - in[2]
    MinusProduct,  // in[2] - t
};

struct ExecInst {
    Op op;
    MulFusion fusion = MulFusion::None;
    bool negatedView = false;  // Specular: in[6..8] hold -V (shadeLight)
    // A light whose results end in sums (LightEpilogue): epilogue[c] its scale's register
    // (-1: none), epilogue[3 + c] its base's; out[] are the sums' registers.
    bool lightEpilogue = false;
    uint8_t nin = 0, nout = 0;
    int32_t imm = 0;
    int32_t in[10] = {};
    int32_t out[3] = {};
    int32_t epilogue[6] = {};
};

class ShaderKernel {
  public:
    static constexpr int kLanes = 128;

    explicit ShaderKernel(const IrProgram& program);

    const IrProgram& program() const { return program_; }
    int registerCount() const { return registerCount_; }
    // The program's instructions but constants (a fused pair counts two).
    size_t instructionCount() const { return instructions_; }
    // The passes over a batch's lanes: instructions, a fused pair (MulFusion) one.
    size_t passCount() const { return code_.size(); }

    // Runs the program on n points. `workspace` is scratch owned by the caller (one per
    // thread); it is sized on first use and then reused without allocation. `stop` (may
    // be null) is checked before the first run of kLanes points and after each: once it
    // says stop, the rest are not run and the call returns false.
    bool run(const ShadingUniforms& uniforms, const ShadingInputs& in, size_t n,
             const ShadingOutputs& out, std::vector<float>& workspace, ShadingCounters& counters,
             const StopSignal* stop = nullptr) const;

  private:
    IrProgram program_;
    std::vector<ExecInst> code_;
    std::vector<std::pair<int32_t, float>> constants_;  // register, value
    int registerCount_ = 0;
    size_t instructions_ = 0;
    int ci_[3] = {-1, -1, -1}, oi_[3] = {-1, -1, -1};
    std::vector<int32_t> channelRegs_;
};

}  // namespace mpshade
