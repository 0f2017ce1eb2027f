#include "shading/ir.h"

#include <sstream>

#include "geometry/error.h"

namespace mpshade {

const char* opName(Op op) {
    static const char* const kNames[] = {"const",   "global",     "param",  "light_ambient",
                                         "channel", "neg",        "abs",    "floor",
                                         "ceil",    "fract",      "sqrt",   "exp",
                                         "log",     "sin",        "cos",    "tan",
                                         "asin",    "acos",       "atan",   "sign",
                                         "trunc",   "not",        "bake",   "dynamic",
                                         "add",     "sub",        "mul",    "div",
                                         "idiv",    "min",        "max",    "mod",
                                         "pow",     "atan2",      "step",   "lt",
                                         "le",      "gt",         "ge",     "eq",
                                         "ne",      "and",        "or",     "clamp",
                                         "mix",     "smoothstep", "select", "noise",
                                         "snoise",  "cellnoise",  "fbm",    "turbulence",
                                         "diffuse", "specular",   "phong",  "occlusion"};
    static_assert(sizeof(kNames) / sizeof(kNames[0]) == static_cast<size_t>(Op::Count));
    return kNames[static_cast<size_t>(op)];
}

bool isPureArithmetic(Op op) {
    return op >= Op::Neg && op <= Op::Turbulence && op != Op::Bake && op != Op::Dynamic;
}

std::string IrProgram::dump() const {
    std::ostringstream out;
    for (const Inst& i : insts) {
        out << "%" << i.result;
        for (int k = 1; k < i.nout; ++k) out << ",%" << (i.result + k);
        out << " = " << opName(i.op);
        if (i.op == Op::Const) out << " " << i.constant;
        if (i.op == Op::Global) out << " " << globalName(static_cast<GlobalId>(i.imm));
        if (i.op == Op::Param || i.op == Op::LightAmbient || i.op == Op::Channel ||
            i.op == Op::Fbm || i.op == Op::Turbulence || i.op >= Op::Diffuse)
            out << " #" << i.imm;
        for (int k = 0; k < i.nargs; ++k) out << " %" << argsOf(i)[k];
        if (i.line > 0) out << "   ; line " << i.line;
        out << "\n";
    }
    if (ci[0] >= 0) out << "Ci = %" << ci[0] << " %" << ci[1] << " %" << ci[2] << "\n";
    if (oi[0] >= 0) out << "Oi = %" << oi[0] << " %" << oi[1] << " %" << oi[2] << "\n";
    for (size_t k = 0; k < channelOutputs.size(); ++k)
        out << "channel " << k << " = %" << channelOutputs[k] << "\n";
    return out.str();
}

IrProgram IrProgram::emptyCopy() const {
    IrProgram p;
    p.shaderName = shaderName;
    p.file = file;
    p.source = source;
    p.animatedParams = animatedParams;
    p.paramFloats = paramFloats;
    p.channelInputs = channelInputs;
    return p;
}

std::vector<int> definingInstructions(const IrProgram& program) {
    std::vector<int> defining(static_cast<size_t>(program.valueCount), -1);
    for (size_t k = 0; k < program.insts.size(); ++k)
        for (int o = 0; o < program.insts[k].nout; ++o)
            defining[static_cast<size_t>(program.insts[k].result + o)] = static_cast<int>(k);
    return defining;
}

void eliminateDeadCode(IrProgram& program) {
    const std::vector<int> defining = definingInstructions(program);
    std::vector<char> live(program.insts.size(), 0);
    std::vector<int> stack;
    for (int v : program.ci)
        if (v >= 0) stack.push_back(v);
    for (int v : program.oi)
        if (v >= 0) stack.push_back(v);
    for (int v : program.channelOutputs) stack.push_back(v);
    while (!stack.empty()) {
        const int v = stack.back();
        stack.pop_back();
        MPSHADE_CHECK(v >= 0 && v < program.valueCount);
        const int k = defining[static_cast<size_t>(v)];
        if (live[static_cast<size_t>(k)]) continue;
        live[static_cast<size_t>(k)] = 1;
        const Inst& inst = program.insts[static_cast<size_t>(k)];
        for (int a = 0; a < inst.nargs; ++a) stack.push_back(program.argsOf(inst)[a]);
    }
    std::vector<int> renumber(static_cast<size_t>(program.valueCount), -1);
    std::vector<Inst> insts;
    std::vector<int32_t> args;
    int next = 0;
    for (size_t k = 0; k < program.insts.size(); ++k) {
        if (!live[k]) continue;
        Inst inst = program.insts[k];
        const int32_t* oldArgs = program.argsOf(inst);
        inst.firstArg = static_cast<int32_t>(args.size());
        for (int a = 0; a < inst.nargs; ++a)
            args.push_back(renumber[static_cast<size_t>(oldArgs[a])]);
        for (int o = 0; o < inst.nout; ++o)
            renumber[static_cast<size_t>(inst.result + o)] = next + o;
        inst.result = next;
        next += inst.nout;
        insts.push_back(inst);
    }
    for (int& v : program.ci)
        if (v >= 0) v = renumber[static_cast<size_t>(v)];
    for (int& v : program.oi)
        if (v >= 0) v = renumber[static_cast<size_t>(v)];
    for (int& v : program.channelOutputs) v = renumber[static_cast<size_t>(v)];
    if (!program.info.empty()) {
        std::vector<ValueInfo> info(static_cast<size_t>(next));
        for (size_t v = 0; v < renumber.size() && v < program.info.size(); ++v)
            if (renumber[v] >= 0)
                info[static_cast<size_t>(renumber[v])] = std::move(program.info[v]);
        program.info = std::move(info);
    }
    program.insts = std::move(insts);
    program.args = std::move(args);
    program.valueCount = next;
}

}  // namespace mpshade
