#include "shading/program_digest.h"

#include <algorithm>

namespace mpshade {

void addProgram(ContentHasher& hasher, const IrProgram& program) {
    hasher.addU64(kEvaluationVersion).addU64(program.insts.size());
    for (const Inst& inst : program.insts) {
        hasher.addI32(static_cast<int32_t>(inst.op))
            .addI32(inst.nargs)
            .addI32(inst.nout)
            .addI32(inst.imm)
            .addFloat(inst.op == Op::Const ? inst.constant : 0.0f)
            .addI32(inst.result);
        const int32_t* args = program.argsOf(inst);
        hasher.addBytes(args, sizeof(int32_t) * inst.nargs);
    }
    hasher.addI32(program.valueCount);
    for (int k = 0; k < 3; ++k) hasher.addI32(program.ci[k]).addI32(program.oi[k]);
    hasher.addU64(program.channelOutputs.size())
        .addBytes(program.channelOutputs.data(), sizeof(int32_t) * program.channelOutputs.size())
        .addI32(program.channelInputs)
        .addI32(program.paramFloats);
}

UniformsRead uniformsRead(const IrProgram& program) {
    UniformsRead r;
    for (const Inst& inst : program.insts) {
        switch (inst.op) {
            case Op::Param:
                for (int c = 0; c < inst.nout; ++c) r.paramFloats.push_back(inst.imm + c);
                break;
            case Op::LightAmbient:
            case Op::Diffuse:
            case Op::Specular:
            case Op::Phong:
                r.lights.push_back(inst.imm);
                break;
            case Op::Occlusion:
                r.occlusion = true;
                break;
            case Op::Global: {
                const auto id = static_cast<GlobalId>(inst.imm);
                r.eye |= id == GlobalId::E || id == GlobalId::I;
                r.time |= id == GlobalId::time;
                break;
            }
            default:
                break;
        }
    }
    for (std::vector<int>* v : {&r.paramFloats, &r.lights}) {
        std::sort(v->begin(), v->end());
        v->erase(std::unique(v->begin(), v->end()), v->end());
    }
    return r;
}

void addUniformsRead(ContentHasher& hasher, const IrProgram& program,
                     const ShadingUniforms& uniforms) {
    const UniformsRead read = uniformsRead(program);
    const std::vector<int>& paramFloats = read.paramFloats;
    const std::vector<int>& lights = read.lights;
    const bool eye = read.eye, time = read.time, occlusion = read.occlusion;
    // Each set is preceded by its size and each value by its index, so which values were
    // read is part of the digest as well as what they were.
    hasher.addU64(paramFloats.size());
    for (int slot : paramFloats) {
        const bool within = slot >= 0 && static_cast<size_t>(slot) < uniforms.params.size();
        hasher.addI32(slot).addFloat(within ? uniforms.params[static_cast<size_t>(slot)] : 0.0f);
    }
    hasher.addU64(lights.size());
    for (int index : lights) {
        hasher.addI32(index);
        if (index < 0 || static_cast<size_t>(index) >= uniforms.lights.size()) continue;
        const LightSample& l = uniforms.lights[static_cast<size_t>(index)];
        hasher.addI32(static_cast<int32_t>(l.kind));
        for (const glm::vec3& v : {l.color, l.position, l.toLight})
            hasher.addFloat(v.x).addFloat(v.y).addFloat(v.z);
    }
    hasher.addI32(eye);
    if (eye) hasher.addFloat(uniforms.eye.x).addFloat(uniforms.eye.y).addFloat(uniforms.eye.z);
    hasher.addI32(time);
    if (time) hasher.addFloat(uniforms.time);
    hasher.addI32(occlusion);
    if (occlusion) hasher.addI32(uniforms.occluder != nullptr).addFloat(uniforms.occlusionBias);
}

}  // namespace mpshade
