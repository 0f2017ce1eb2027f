#include "shading/binding_time.h"

namespace mpshade {

bool isDiscontinuous(Op op) {
    switch (op) {
        case Op::Floor:
        case Op::Ceil:
        case Op::Fract:
        case Op::Sign:
        case Op::Trunc:
        case Op::Not:
        case Op::IDiv:
        case Op::Mod:
        case Op::Step:
        case Op::Lt:
        case Op::Le:
        case Op::Gt:
        case Op::Ge:
        case Op::Eq:
        case Op::Ne:
        case Op::And:
        case Op::Or:
        case Op::Select:
        case Op::Cellnoise:
            return true;
        default:
            return false;
    }
}

bool mayRecompute(Op op, int imm, const FactorOptions& options) {
    return opCost(op, imm) <= options.recomputeCostLimit &&
           !(options.storeDiscontinuities && isDiscontinuous(op));
}

int opCost(Op op, int imm) {
    switch (op) {
        case Op::Const:
        case Op::Global:
        case Op::Param:
        case Op::LightAmbient:
        case Op::Channel:
        case Op::Bake:
        case Op::Dynamic:
            return 0;
        case Op::Sqrt:
        case Op::Div:
        case Op::IDiv:
        case Op::Mod:
        case Op::Smoothstep:
            return 2;
        case Op::Exp:
        case Op::Log:
        case Op::Sin:
        case Op::Cos:
        case Op::Tan:
        case Op::Asin:
        case Op::Acos:
        case Op::Atan:
        case Op::Atan2:
        case Op::Pow:
            return 8;
        case Op::Noise:
        case Op::Snoise:
        case Op::Cellnoise:
            return 40;
        case Op::Fbm:
        case Op::Turbulence:
            return 40 * (imm > 0 ? imm : 1);
        case Op::Diffuse:
        case Op::Specular:
        case Op::Phong:
            return 30;
        case Op::Occlusion:
            return 200 * (imm > 0 ? imm : 1);
        default:
            return 1;
    }
}

namespace {

bool isGeometry(GlobalId id) {
    return id != GlobalId::I && id != GlobalId::E && id != GlobalId::time;
}

const char* globalWhy(GlobalId id) {
    switch (id) {
        case GlobalId::I:
            return "I, the direction from the eye, changes with the view";
        case GlobalId::E:
            return "E, the eye position, changes with the view";
        case GlobalId::time:
            return "time changes every frame";
        default:
            return "";
    }
}

// dynamic(x) evaluates x every frame: the static work under it moves to the dynamic part
// (down to free values), and whatever uses it follows. Marks it in `forced` and
// bt.forcedBy; true if anything moved.
bool forceUnderDynamic(const IrProgram& program, BindingTimes& bt, std::vector<char>& forced) {
    bool anyForced = false;
    const std::vector<int> defining = definingInstructions(program);
    for (size_t d = 0; d < program.insts.size(); ++d) {
        const Inst& dyn = program.insts[d];
        if (dyn.op != Op::Dynamic) continue;
        std::vector<int32_t> stack(program.argsOf(dyn), program.argsOf(dyn) + dyn.nargs);
        while (!stack.empty()) {
            const size_t v = static_cast<size_t>(stack.back());
            stack.pop_back();
            if (forced[v] || bt.stage[v] != Stage::Static) continue;
            const Inst& inst = program.insts[static_cast<size_t>(defining[v])];
            if (inst.op == Op::Bake) continue;  // an explicit bake wins
            forced[v] = 1;
            bt.forcedBy[v] = static_cast<int32_t>(d);
            anyForced = true;
            for (int a = 0; a < inst.nargs; ++a) stack.push_back(program.argsOf(inst)[a]);
        }
    }
    return anyForced;
}

}  // namespace

BindingTimes analyzeBindingTimes(const IrProgram& program, const ShaderBinding& binding,
                                 const FactorOptions& options) {
    const size_t n = static_cast<size_t>(program.valueCount);
    BindingTimes bt;
    bt.stage.assign(n, Stage::Free);
    bt.cause.assign(n, -1);
    bt.why.assign(n, {});
    bt.lightMoves.assign(n, 0);
    std::vector<char> forced(n, 0);                // made dynamic by a dynamic() override
    std::vector<int32_t>& forcedBy = bt.forcedBy;  // the dynamic() instruction that forced it
    forcedBy.assign(n, -1);

    // Who asks a Dynamic instruction's value to be repeated: a dynamic() in the source, or
    // (imm k + 1, lower.cpp) the binding's factoring override k.
    auto askedBy = [&](const Inst& dyn) -> std::string {
        const auto k = static_cast<size_t>(dyn.imm);
        if (k == 0 || k > binding.overrides.size()) return "dynamic() asks for it";
        return "the binding repeats '" + binding.overrides[k - 1].spelled + "'";
    };

    auto pass = [&]() {
        for (const Inst& inst : program.insts) {
            const int32_t* args = program.argsOf(inst);
            Stage stage = Stage::Free;
            int32_t cause = -1;
            std::string why;
            for (int a = 0; a < inst.nargs; ++a) {
                const Stage s = bt.stage[static_cast<size_t>(args[a])];
                if (s > stage) stage = s;
                if (s == Stage::Dynamic && cause < 0) cause = args[a];
            }
            switch (inst.op) {
                case Op::Const:
                    stage = Stage::Free;
                    break;
                case Op::Global: {
                    const auto id = static_cast<GlobalId>(inst.imm);
                    if (!isGeometry(id)) {
                        stage = Stage::Dynamic;
                        why = globalWhy(id);
                    } else {
                        stage = options.geometryInDynamicPhase ? Stage::Free : Stage::Static;
                    }
                    break;
                }
                case Op::Param:
                    stage = Stage::Dynamic;
                    for (const AnimatedParam& p : program.animatedParams)
                        if (p.slot <= inst.imm && inst.imm < p.slot + p.components)
                            why = "parameter '" + p.name + "' is animated";
                    break;
                case Op::LightAmbient:
                    stage = Stage::Dynamic;
                    why = "ambient light " + std::to_string(inst.imm) + " is animated";
                    break;
                case Op::Channel:
                    stage = Stage::Static;
                    break;
                case Op::Bake:
                    // Evaluated in the static phase at the range's representative values.
                    stage = Stage::Static;
                    cause = -1;
                    break;
                case Op::Dynamic:
                    stage = Stage::Dynamic;
                    if (cause < 0) why = askedBy(inst);
                    break;
                case Op::Diffuse:
                case Op::Specular:
                case Op::Phong: {
                    const size_t light = static_cast<size_t>(inst.imm);
                    const bool moves = light < binding.lights.size() &&
                                       binding.lights[light].movesRelativeToObject;
                    for (int o = 0; o < inst.nout; ++o)
                        bt.lightMoves[static_cast<size_t>(inst.result + o)] = moves ? 1 : 0;
                    if (moves && stage != Stage::Dynamic) {
                        stage = Stage::Dynamic;
                        cause = -1;
                        why = "light " + std::to_string(light) + " moves relative to the object";
                    } else if (stage == Stage::Free) {
                        stage = Stage::Static;  // lighting is never repeated for free
                    }
                    break;
                }
                default:
                    // Free values feed cheap arithmetic for free; expensive work on them is static.
                    if (stage == Stage::Free && !mayRecompute(inst.op, inst.imm, options))
                        stage = Stage::Static;
                    break;
            }
            for (int o = 0; o < inst.nout; ++o) {
                const size_t v = static_cast<size_t>(inst.result + o);
                if (forced[v] && stage != Stage::Dynamic) {
                    stage = Stage::Dynamic;
                    why = askedBy(program.insts[static_cast<size_t>(forcedBy[v])]);
                    cause = -1;
                }
                bt.stage[v] = stage;
                bt.cause[v] = stage == Stage::Dynamic ? cause : -1;
                bt.why[v] = stage == Stage::Dynamic && cause < 0 ? why : std::string();
            }
        }
    };
    pass();

    if (forceUnderDynamic(program, bt, forced)) pass();
    return bt;
}

}  // namespace mpshade
