#include "shading/interpreter.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <span>

#include <glm/geometric.hpp>

#include "geometry/error.h"
#include "shading/lighting.h"
#include "shading/noise.h"
#include "shading/scalar_ops.h"

namespace mpshade {
namespace {

template <Op OP>
[[gnu::always_inline]] inline void unaryLoop(float* o, const float* a, int m) {
    for (int l = 0; l < m; ++l) o[l] = scalar::unary(OP, a[l]);
}
template <Op OP>
[[gnu::always_inline]] inline void binaryLoop(float* o, const float* a, const float* b, int m) {
    for (int l = 0; l < m; ++l) o[l] = scalar::binary(OP, a[l], b[l]);
}
template <Op OP>
[[gnu::always_inline]] inline void ternaryLoop(float* o, const float* a, const float* b,
                                               const float* c, int m) {
    for (int l = 0; l < m; ++l) o[l] = scalar::ternary(OP, a[l], b[l], c[l]);
}

template <MulFusion F>
[[gnu::always_inline]] inline void fusedLoop(float* o, const float* a, const float* b,
                                             const float* c, int m) {
    for (int l = 0; l < m; ++l) {
        const float t = a[l] * b[l];
        if constexpr (F == MulFusion::ProductPlus) o[l] = t + c[l];
        if constexpr (F == MulFusion::PlusProduct) o[l] = c[l] + t;
        if constexpr (F == MulFusion::ProductMinus) o[l] = t - c[l];
        if constexpr (F == MulFusion::MinusProduct) o[l] = c[l] - t;
    }
}

constexpr float kNoOperand[ShaderKernel::kLanes] = {};

// One batch of m lanes (from `start`) through the whole program. Cloned for AVX2 and the
// baseline, chosen at run time: every op's loop over the lanes is inlined here, so the
// AVX2 clone runs them eight lanes at a time. AVX2 implies no FMA, so nothing is
// contracted and both clones give the same bits.
__attribute__((target_clones("avx2", "default"))) void runBatch(
    std::span<const ExecInst> code, const ShadingUniforms& uniforms, const ShadingInputs& in,
    size_t start, int m, float* regs, const float** S, ShadingCounters& counters,
    const StopSignal* stop) {
    auto R = [&](int32_t r) { return regs + static_cast<size_t>(r) * ShaderKernel::kLanes; };
    for (const ExecInst& e : code) {
        float* o = R(e.out[0]);
        // An operand the op does not have reads zeros (no op reads past its own).
        const float* a = e.nin > 0 ? S[e.in[0]] : kNoOperand;
        const float* b = e.nin > 1 ? S[e.in[1]] : kNoOperand;
        const float* c = e.nin > 2 ? S[e.in[2]] : kNoOperand;
        for (int k = 0; k < e.nout; ++k) S[e.out[k]] = R(e.out[k]);
        switch (e.fusion) {
            case MulFusion::None:
                break;
// clang-format off (it cannot lay out these case-making macros)
#define MPSHADE_FUSED(X)                        \
    case MulFusion::X:                          \
        fusedLoop<MulFusion::X>(o, a, b, c, m); \
        continue;
                MPSHADE_FUSED(ProductPlus)
                MPSHADE_FUSED(PlusProduct)
                MPSHADE_FUSED(ProductMinus)
                MPSHADE_FUSED(MinusProduct)
#undef MPSHADE_FUSED
                // clang-format on
        }
        switch (e.op) {
            case Op::Global: {
                const auto id = static_cast<GlobalId>(e.imm);
                const float* const* src = nullptr;
                const float* scalarSrc = nullptr;
                switch (id) {
                    case GlobalId::P:
                        src = in.P;
                        break;
                    case GlobalId::N:
                        src = in.N;
                        break;
                    case GlobalId::Ng:
                        src = in.Ng;
                        break;
                    case GlobalId::dPdu:
                        src = in.dPdu;
                        break;
                    case GlobalId::dPdv:
                        src = in.dPdv;
                        break;
                    case GlobalId::I:
                        src = in.I;
                        break;
                    case GlobalId::u:
                        scalarSrc = in.u;
                        break;
                    case GlobalId::v:
                        scalarSrc = in.v;
                        break;
                    case GlobalId::s:
                        scalarSrc = in.s;
                        break;
                    case GlobalId::t:
                        scalarSrc = in.t;
                        break;
                    case GlobalId::E:
                        for (int k = 0; k < 3; ++k) std::fill_n(R(e.out[k]), m, uniforms.eye[k]);
                        break;
                    case GlobalId::time:
                        std::fill_n(o, m, uniforms.time);
                        break;
                    case GlobalId::Count:
                        break;
                }
                if (src) {
                    for (int k = 0; k < 3; ++k) {
                        MPSHADE_CHECK(src[k] != nullptr);
                        S[e.out[k]] = src[k] + start;
                    }
                } else if (scalarSrc) {
                    S[e.out[0]] = scalarSrc + start;
                }
                break;
            }
            case Op::Param:
                for (int k = 0; k < e.nout; ++k)
                    std::fill_n(R(e.out[k]), m, uniforms.params[static_cast<size_t>(e.imm + k)]);
                break;
            case Op::Channel:
                MPSHADE_CHECK(in.channels != nullptr);
                S[e.out[0]] = in.channels[e.imm] + start;
                break;
            case Op::LightAmbient:
                for (int k = 0; k < 3; ++k)
                    std::fill_n(R(e.out[k]), m,
                                uniforms.lights[static_cast<size_t>(e.imm)].color[k]);
                break;
// clang-format off (it cannot lay out these case-making macros)
#define MPSHADE_UNARY(X)           \
    case Op::X:                    \
        unaryLoop<Op::X>(o, a, m); \
        break;
                MPSHADE_UNARY(Neg)
                MPSHADE_UNARY(Abs)
                MPSHADE_UNARY(Floor)
                MPSHADE_UNARY(Ceil)
                MPSHADE_UNARY(Fract)
                MPSHADE_UNARY(Sqrt)
                MPSHADE_UNARY(Exp)
                MPSHADE_UNARY(Log)
                MPSHADE_UNARY(Sin)
                MPSHADE_UNARY(Cos)
                MPSHADE_UNARY(Tan)
                MPSHADE_UNARY(Asin)
                MPSHADE_UNARY(Acos)
                MPSHADE_UNARY(Atan)
                MPSHADE_UNARY(Sign)
                MPSHADE_UNARY(Trunc)
                MPSHADE_UNARY(Not)
                MPSHADE_UNARY(Bake)
                MPSHADE_UNARY(Dynamic)
#undef MPSHADE_UNARY
#define MPSHADE_BINARY(X)              \
    case Op::X:                        \
        binaryLoop<Op::X>(o, a, b, m); \
        break;
                MPSHADE_BINARY(Add)
                MPSHADE_BINARY(Sub)
                MPSHADE_BINARY(Mul)
                MPSHADE_BINARY(Div)
                MPSHADE_BINARY(IDiv)
                MPSHADE_BINARY(Min)
                MPSHADE_BINARY(Max)
                MPSHADE_BINARY(Mod)
                MPSHADE_BINARY(Pow)
                MPSHADE_BINARY(Atan2)
                MPSHADE_BINARY(Step)
                MPSHADE_BINARY(Lt)
                MPSHADE_BINARY(Le)
                MPSHADE_BINARY(Gt)
                MPSHADE_BINARY(Ge)
                MPSHADE_BINARY(Eq)
                MPSHADE_BINARY(Ne)
                MPSHADE_BINARY(And)
                MPSHADE_BINARY(Or)
#undef MPSHADE_BINARY
#define MPSHADE_TERNARY(X)                 \
    case Op::X:                            \
        ternaryLoop<Op::X>(o, a, b, c, m); \
        break;
                MPSHADE_TERNARY(Clamp)
                MPSHADE_TERNARY(Mix)
                MPSHADE_TERNARY(Smoothstep)
                MPSHADE_TERNARY(Select)
#undef MPSHADE_TERNARY
                // clang-format on
            case Op::Snoise:
                snoise3Lanes(a, b, c, o, m);
                break;
            case Op::Noise:
                noise3Lanes(a, b, c, o, m);
                break;
            case Op::Fbm:
                fbm3Lanes(a, b, c, e.imm, o, m);
                break;
            case Op::Turbulence:
                turbulence3Lanes(a, b, c, e.imm, o, m);
                break;
            case Op::Cellnoise:
                for (int l = 0; l < m; ++l) o[l] = cellnoise3(a[l], b[l], c[l]);
                break;
            case Op::Diffuse:
            case Op::Specular:
            case Op::Phong: {
                const LightSample& light = uniforms.lights[static_cast<size_t>(e.imm)];
                const float* arg[10];
                for (int k = 0; k < e.nin; ++k) arg[k] = S[e.in[k]];
                float* rgb[3] = {R(e.out[0]), R(e.out[1]), R(e.out[2])};
                LightEpilogue epilogue;
                if (e.lightEpilogue)
                    for (int k = 0; k < 3; ++k) {
                        epilogue.scale[k] = e.epilogue[k] >= 0 ? S[e.epilogue[k]] : nullptr;
                        epilogue.base[k] = S[e.epilogue[3 + k]];
                    }
                shadeLight(e.op, light, arg, rgb, m, e.negatedView,
                           e.lightEpilogue ? &epilogue : nullptr);
                break;
            }
            case Op::Occlusion: {
                const float* arg[6];
                for (int k = 0; k < 6; ++k) arg[k] = S[e.in[k]];
                counters.occlusionRays += occlusionLanes(uniforms.occluder, uniforms.occlusionBias,
                                                         e.imm, arg, o, m, stop);
                break;
            }
            case Op::Const:
            case Op::Count:
                break;
        }
    }
}

// A specular(N, -I, r) reads its view through three negations, a pass over the lanes
// each: where every reader of a negation is a Specular's view, those Speculars read the
// negation's argument instead (negatedView) and the negation is no longer run. Rewrites
// `program`'s arguments; marks the Speculars and the negations left unread.
void readNegatedViews(IrProgram& program, std::vector<char>& negatedView,
                      std::vector<char>& unread) {
    const size_t count = program.insts.size();
    negatedView.assign(count, 0);
    unread.assign(count, 0);
    std::vector<int> producer(static_cast<size_t>(program.valueCount), -1);
    for (size_t k = 0; k < count; ++k)
        for (int o = 0; o < program.insts[k].nout; ++o)
            producer[static_cast<size_t>(program.insts[k].result + o)] = static_cast<int>(k);
    // Values kept as results, or read other than as a Specular's view, keep their negation.
    std::vector<char> otherUse(static_cast<size_t>(program.valueCount), 0);
    for (const int v : program.ci)
        if (v >= 0) otherUse[static_cast<size_t>(v)] = 1;
    for (const int v : program.oi)
        if (v >= 0) otherUse[static_cast<size_t>(v)] = 1;
    for (const int v : program.channelOutputs) otherUse[static_cast<size_t>(v)] = 1;
    for (const Inst& inst : program.insts)
        for (int a = 0; a < inst.nargs; ++a)
            if (!(inst.op == Op::Specular && a >= 6 && a <= 8))
                otherUse[static_cast<size_t>(program.argsOf(inst)[a])] = 1;
    auto negation = [&](int32_t v) {
        const int k = producer[static_cast<size_t>(v)];
        return k >= 0 && program.insts[static_cast<size_t>(k)].op == Op::Neg &&
               program.insts[static_cast<size_t>(k)].nargs == 1 &&
               !otherUse[static_cast<size_t>(v)];
    };
    std::vector<char> negationRead(count, 0);
    for (size_t k = 0; k < count; ++k) {
        const Inst& inst = program.insts[k];
        if (inst.op != Op::Specular || inst.nargs < 9) continue;
        int32_t* args = program.args.data() + inst.firstArg;
        if (!(negation(args[6]) && negation(args[7]) && negation(args[8]))) {
            for (int a = 6; a <= 8; ++a) {
                const int p = producer[static_cast<size_t>(args[a])];
                if (p >= 0) negationRead[static_cast<size_t>(p)] = 1;
            }
            continue;
        }
        negatedView[k] = 1;
        for (int a = 6; a <= 8; ++a) {
            const Inst& neg =
                program.insts[static_cast<size_t>(producer[static_cast<size_t>(args[a])])];
            args[a] = program.argsOf(neg)[0];
        }
    }
    for (size_t k = 0; k < count; ++k)
        if (program.insts[k].op == Op::Neg && !negationRead[k] &&
            !otherUse[static_cast<size_t>(program.insts[k].result)])
            unread[k] = 1;
}

// How many times each value is read (an instruction reading it twice counts twice).
std::vector<int> useCounts(const IrProgram& program) {
    std::vector<int> uses(static_cast<size_t>(program.valueCount), 0);
    for (const Inst& inst : program.insts)
        for (int a = 0; a < inst.nargs; ++a) ++uses[static_cast<size_t>(program.argsOf(inst)[a])];
    return uses;
}

// Per instruction, the product fused into it (the inverse of fusedInto), else -1.
std::vector<int> productsFused(const std::vector<int>& fusedInto) {
    std::vector<int> fusedFrom(fusedInto.size(), -1);
    for (size_t k = 0; k < fusedInto.size(); ++k)
        if (fusedInto[k] >= 0) fusedFrom[static_cast<size_t>(fusedInto[k])] = static_cast<int>(k);
    return fusedFrom;
}

// For each instruction, the index of the addition or subtraction its product is fused
// into (MulFusion), else -1: a one-result Mul whose value only that instruction reads, once,
// and that no output keeps (lastUse past the program).
std::vector<int> findMulFusions(const IrProgram& program, const std::vector<int>& uses,
                                const std::vector<int>& lastUse) {
    const size_t count = program.insts.size();
    std::vector<int> fusedInto(count, -1);
    std::vector<char> absorbs(count, 0);
    for (size_t k = 0; k < count; ++k) {
        const Inst& mul = program.insts[k];
        if (mul.op != Op::Mul || mul.nout != 1 || mul.nargs != 2) continue;
        const auto v = static_cast<size_t>(mul.result);
        const int reader = lastUse[v];
        if (uses[v] != 1 || reader < 0 || reader >= static_cast<int>(count)) continue;
        const Inst& add = program.insts[static_cast<size_t>(reader)];
        if ((add.op != Op::Add && add.op != Op::Sub) || add.nargs != 2 || add.nout != 1 ||
            absorbs[static_cast<size_t>(reader)])
            continue;
        fusedInto[k] = reader;
        absorbs[static_cast<size_t>(reader)] = 1;
    }
    return fusedInto;
}

// A light instruction's three results each ending in a sum (LightEpilogue): per channel the
// sum's index and the values of scale (-1 if the light is the sum's own operand, no
// product) and base.
struct LightEnding {
    int sum[3] = {-1, -1, -1};
    int32_t scale[3] = {-1, -1, -1};
    int32_t base[3] = {-1, -1, -1};
};

// For each light instruction (diffuse, specular, phong) whose every result is read once, by
// an addition (light + base) or by a product fused into an addition (scale * light + base),
// with scale and base made before the light: how it ends, so it is written in the light's
// own pass. A sum already absorbing another light or a product of its own is left alone.
std::vector<LightEnding> findLightEndings(const IrProgram& program, const std::vector<int>& uses,
                                          const std::vector<int>& lastUse,
                                          const std::vector<int>& fusedInto,
                                          const std::vector<int>& fusedFrom,
                                          std::vector<char>& ends) {
    const size_t count = program.insts.size();
    std::vector<int> madeAt(uses.size(), -1);
    for (size_t k = 0; k < count; ++k)
        for (int o = 0; o < program.insts[k].nout; ++o)
            madeAt[static_cast<size_t>(program.insts[k].result + o)] = static_cast<int>(k);
    std::vector<LightEnding> endings(count);
    ends.assign(count, 0);
    for (size_t k = 0; k < count; ++k) {
        const Inst& light = program.insts[k];
        if ((light.op != Op::Diffuse && light.op != Op::Specular && light.op != Op::Phong) ||
            light.nout != 3)
            continue;
        auto before = [&](int32_t v) {
            return madeAt[static_cast<size_t>(v)] < static_cast<int>(k);
        };
        auto other = [&](const Inst& inst, int32_t v) {
            const int32_t* args = program.argsOf(inst);
            return args[0] == v ? args[1] : args[0];
        };
        LightEnding end;
        bool ok = true;
        for (int c = 0; c < 3 && ok; ++c) {
            const int32_t v = light.result + c;
            const int reader = lastUse[static_cast<size_t>(v)];
            ok = uses[static_cast<size_t>(v)] == 1 && reader >= 0 &&
                 reader < static_cast<int>(count);
            if (!ok) break;
            const Inst& r = program.insts[static_cast<size_t>(reader)];
            int sum = reader;
            int32_t operand = v;  // what the sum reads of this channel
            if (r.op == Op::Mul && fusedInto[static_cast<size_t>(reader)] >= 0) {
                end.scale[c] = other(r, v);
                ok = before(end.scale[c]);
                sum = fusedInto[static_cast<size_t>(reader)];
                operand = r.result;
            } else {
                ok = fusedFrom[static_cast<size_t>(reader)] < 0;  // no product of its own
            }
            const Inst& s = program.insts[static_cast<size_t>(sum)];
            ok = ok && s.op == Op::Add && s.nargs == 2 && s.nout == 1 &&
                 !ends[static_cast<size_t>(sum)];
            if (!ok) break;
            end.sum[c] = sum;
            end.base[c] = other(s, operand);
            ok = before(end.base[c]) && end.base[c] != operand;
        }
        const bool oneKind =
            (end.scale[0] < 0) == (end.scale[1] < 0) && (end.scale[0] < 0) == (end.scale[2] < 0);
        if (!ok || !oneKind) continue;
        endings[k] = end;
        for (int c = 0; c < 3; ++c) ends[static_cast<size_t>(end.sum[c])] = 1;
    }
    return endings;
}

// The last instruction reading each value (-1: none); outputs live to the end (INT_MAX).
std::vector<int> lastReaders(const IrProgram& program) {
    std::vector<int> lastUse(static_cast<size_t>(program.valueCount), -1);
    for (size_t k = 0; k < program.insts.size(); ++k) {
        const Inst& inst = program.insts[k];
        for (int a = 0; a < inst.nargs; ++a)
            lastUse[static_cast<size_t>(program.argsOf(inst)[a])] = static_cast<int>(k);
    }
    auto keepToTheEnd = [&](int v) {
        if (v >= 0) lastUse[static_cast<size_t>(v)] = std::numeric_limits<int>::max();
    };
    for (int v : program.ci) keepToTheEnd(v);
    for (int v : program.oi) keepToTheEnd(v);
    for (int v : program.channelOutputs) keepToTheEnd(v);
    return lastUse;
}

// A fused product's arguments are read where its sum is: their last use moved there.
void readProductsAtTheirSums(const IrProgram& program, const std::vector<int>& fusedInto,
                             std::vector<int>& lastUse) {
    for (size_t k = 0; k < program.insts.size(); ++k) {
        if (fusedInto[k] < 0) continue;
        const Inst& mul = program.insts[k];
        for (int a = 0; a < mul.nargs; ++a) {
            int& last = lastUse[static_cast<size_t>(program.argsOf(mul)[a])];
            last = std::max(last, fusedInto[k]);
        }
    }
}

}  // namespace

ShaderKernel::ShaderKernel(const IrProgram& source) : program_(source) {
    IrProgram program = source;
    std::vector<char> negatedView, unread;
    readNegatedViews(program, negatedView, unread);
    std::vector<int> lastUse = lastReaders(program);
    const std::vector<int> uses = useCounts(program);
    const std::vector<int> fusedInto = findMulFusions(program, uses, lastUse);
    const std::vector<int> fusedFrom = productsFused(fusedInto);
    std::vector<char> endsLight;  // a sum written by the light before it
    const std::vector<LightEnding> lightEndings =
        findLightEndings(program, uses, lastUse, fusedInto, fusedFrom, endsLight);

    std::vector<int32_t> reg(static_cast<size_t>(program.valueCount), -1);
    std::vector<char> constantReg;
    std::vector<int32_t> freeRegs;
    auto allocate = [&]() {
        if (!freeRegs.empty()) {
            const int32_t r = freeRegs.back();
            freeRegs.pop_back();
            return r;
        }
        constantReg.push_back(0);
        return static_cast<int32_t>(registerCount_++);
    };
    // Constants first: each keeps a register of its own for the whole run, filled once.
    for (const Inst& inst : program.insts) {
        if (inst.op != Op::Const) continue;
        const int32_t r = allocate();
        reg[static_cast<size_t>(inst.result)] = r;
        constantReg[static_cast<size_t>(r)] = 1;
        constants_.emplace_back(r, inst.constant);
    }
    readProductsAtTheirSums(program, fusedInto, lastUse);
    // Value v's register back to the pool if instruction k is its last reader.
    auto releaseAfter = [&](int32_t v, size_t k) {
        int& last = lastUse[static_cast<size_t>(v)];
        const int32_t r = reg[static_cast<size_t>(v)];
        if (last == static_cast<int>(k) && !constantReg[static_cast<size_t>(r)]) {
            freeRegs.push_back(r);
            last = -2;  // freed; a repeated argument is not freed twice
        }
    };
    for (size_t k = 0; k < program.insts.size(); ++k) {
        const Inst& inst = program.insts[k];
        if (inst.op == Op::Const) continue;
        ++instructions_;
        if (endsLight[k]) {
            // Written by its light; its scale's and base's reads were there, but they live
            // until here.
            auto release = [&](int32_t v) {
                if (reg[static_cast<size_t>(v)] >= 0) releaseAfter(v, k);  // not the light's
            };
            if (fusedFrom[k] >= 0) {
                const Inst& mul = program.insts[static_cast<size_t>(fusedFrom[k])];
                for (int a = 0; a < mul.nargs; ++a) release(program.argsOf(mul)[a]);
            }
            for (int a = 0; a < inst.nargs; ++a) release(program.argsOf(inst)[a]);
            continue;
        }
        if (fusedInto[k] >= 0 || unread[k]) continue;  // emitted with its reader, or not needed
        ExecInst e;
        e.op = inst.op;
        e.nin = inst.nargs;
        e.nout = inst.nout;
        e.imm = inst.imm;
        e.negatedView = negatedView[k] != 0;
        const int32_t* args = program.argsOf(inst);
        for (int a = 0; a < inst.nargs; ++a) e.in[a] = reg[static_cast<size_t>(args[a])];
        const Inst* mul =
            fusedFrom[k] >= 0 ? &program.insts[static_cast<size_t>(fusedFrom[k])] : nullptr;
        if (mul) {
            const int32_t* margs = program.argsOf(*mul);
            const bool productFirst = args[0] == mul->result;
            const int32_t other = e.in[productFirst ? 1 : 0];
            e.op = Op::Mul;
            e.fusion = inst.op == Op::Add
                           ? (productFirst ? MulFusion::ProductPlus : MulFusion::PlusProduct)
                           : (productFirst ? MulFusion::ProductMinus : MulFusion::MinusProduct);
            e.nin = 3;
            e.in[0] = reg[static_cast<size_t>(margs[0])];
            e.in[1] = reg[static_cast<size_t>(margs[1])];
            e.in[2] = other;
        }
        // A light ending in sums writes them (their values' registers, made here).
        const LightEnding& ending = lightEndings[k];
        const bool ends = ending.sum[0] >= 0;
        int32_t outValue[3] = {inst.result, inst.result + 1, inst.result + 2};
        if (ends) {
            e.lightEpilogue = true;
            for (int c = 0; c < 3; ++c) {
                e.epilogue[c] =
                    ending.scale[c] >= 0 ? reg[static_cast<size_t>(ending.scale[c])] : -1;
                e.epilogue[3 + c] = reg[static_cast<size_t>(ending.base[c])];
                outValue[c] = program.insts[static_cast<size_t>(ending.sum[c])].result;
            }
        }
        // Outputs never share a register with this instruction's own inputs.
        for (int o = 0; o < inst.nout; ++o)
            e.out[o] = reg[static_cast<size_t>(outValue[o])] = allocate();
        // A fused product's arguments are read here; the product itself never had a register.
        if (mul)
            for (int a = 0; a < mul->nargs; ++a) releaseAfter(program.argsOf(*mul)[a], k);
        for (int a = 0; a < inst.nargs; ++a)
            if (!mul || args[a] != mul->result) releaseAfter(args[a], k);
        // Results nobody reads are dead at once.
        for (int o = 0; o < inst.nout; ++o)
            if (lastUse[static_cast<size_t>(outValue[o])] == -1) freeRegs.push_back(e.out[o]);
        code_.push_back(e);
    }
    for (int k = 0; k < 3; ++k) {
        if (program.ci[k] >= 0) ci_[k] = reg[static_cast<size_t>(program.ci[k])];
        if (program.oi[k] >= 0) oi_[k] = reg[static_cast<size_t>(program.oi[k])];
    }
    for (int v : program.channelOutputs) channelRegs_.push_back(reg[static_cast<size_t>(v)]);
}

bool ShaderKernel::run(const ShadingUniforms& uniforms, const ShadingInputs& in, size_t n,
                       const ShadingOutputs& out, std::vector<float>& workspace,
                       ShadingCounters& counters, const StopSignal* stop) const {
    const size_t need = static_cast<size_t>(registerCount_) * kLanes;
    if (workspace.size() < need) workspace.resize(need);
    float* regs = workspace.data();
    auto R = [&](int32_t r) { return regs + static_cast<size_t>(r) * kLanes; };
    for (const auto& [r, value] : constants_) std::fill_n(R(r), kLanes, value);
    // Where each register's lanes are read from: its own storage, or -- for a global or an
    // n-tuple channel -- the input array itself, which is then read in place instead of
    // copied in. A register written by an instruction reads from its storage again.
    thread_local std::vector<const float*> sources;
    sources.resize(static_cast<size_t>(registerCount_));
    const float** S = sources.data();
    for (int32_t r = 0; r < registerCount_; ++r) S[r] = R(r);

    if (stop && stop->stopped()) return false;
    for (size_t start = 0; start < n; start += kLanes) {
        const int m = static_cast<int>(std::min<size_t>(kLanes, n - start));
        runBatch(code_, uniforms, in, start, m, regs, S, counters, stop);
        // Stopped within the batch (an occlusion op's rays cut short, its results not
        // whole) or at its end: either way the next batch does not run.
        if (stop && stop->stopped()) return false;
        const size_t bytes = sizeof(float) * static_cast<size_t>(m);
        for (int k = 0; k < 3; ++k) {
            if (ci_[k] >= 0) std::memcpy(out.Ci[k] + start, S[ci_[k]], bytes);
            if (oi_[k] >= 0) std::memcpy(out.Oi[k] + start, S[oi_[k]], bytes);
        }
        for (size_t k = 0; k < channelRegs_.size(); ++k)
            std::memcpy(out.channels[k] + start, S[channelRegs_[k]], bytes);
        counters.instructions += instructions_ * static_cast<uint64_t>(m);
    }
    counters.points += n;
    return true;
}

}  // namespace mpshade
