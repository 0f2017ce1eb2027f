#include "shading/ir_builder.h"

#include <cstring>

#include "shading/scalar_ops.h"

namespace mpshade {

int IrBuilder::constant(float value) {
    uint32_t bits;
    std::memcpy(&bits, &value, sizeof bits);
    auto it = constants_.find(bits);
    if (it != constants_.end()) return it->second;
    Inst inst;
    inst.op = Op::Const;
    inst.constant = value;
    inst.result = program_.valueCount++;
    inst.firstArg = static_cast<int32_t>(program_.args.size());
    inst.line = line_;
    inst.column = column_;
    program_.insts.push_back(inst);
    constOf_.resize(static_cast<size_t>(program_.valueCount), -1);
    constOf_[static_cast<size_t>(inst.result)] = static_cast<int>(constValues_.size());
    constValues_.push_back(value);
    constants_[bits] = inst.result;
    return inst.result;
}

bool IrBuilder::constantValue(int value, float& out) const {
    if (value < 0 || static_cast<size_t>(value) >= constOf_.size()) return false;
    const int k = constOf_[static_cast<size_t>(value)];
    if (k < 0) return false;
    out = constValues_[static_cast<size_t>(k)];
    return true;
}

int IrBuilder::emit(Op op, const std::vector<int>& args, int nout, int imm) {
    float c[10] = {};
    bool allConst = !args.empty();
    for (size_t k = 0; k < args.size(); ++k) allConst = allConst && constantValue(args[k], c[k]);

    // Markers of factoring overrides on constants mean nothing: a constant is static.
    if ((op == Op::Bake || op == Op::Dynamic) && allConst) return args[0];
    if (isPureArithmetic(op) && allConst && nout == 1) {
        ++stats_.folded;
        switch (args.size()) {
            case 1:
                return constant(scalar::unary(op, c[0]));
            case 2:
                return constant(scalar::binary(op, c[0], c[1]));
            case 3:
                if (op >= Op::Noise) return constant(scalar::pattern(op, imm, c[0], c[1], c[2]));
                return constant(scalar::ternary(op, c[0], c[1], c[2]));
            default:
                --stats_.folded;
                break;
        }
    }
    // Identities that hold for every float, NaN, infinities and signed zeros included:
    // x - (+0), x + (-0), x * 1 and x / 1 are x; x + (+0) is not (-0 + 0 is +0).
    auto isConst = [&](size_t k, float value, bool negative = false) {
        float x;
        return constantValue(args[k], x) && x == value && std::signbit(x) == negative;
    };
    if (args.size() == 2) {
        if ((op == Op::Add && isConst(1, 0.0f, true)) || (op == Op::Sub && isConst(1, 0.0f)) ||
            (op == Op::Mul && isConst(1, 1.0f)) || (op == Op::Div && isConst(1, 1.0f))) {
            ++stats_.identities;
            return args[0];
        }
        if ((op == Op::Add && isConst(0, 0.0f, true)) || (op == Op::Mul && isConst(0, 1.0f))) {
            ++stats_.identities;
            return args[1];
        }
    }
    if (op == Op::Select) {
        float cond;
        if (constantValue(args[0], cond)) {
            ++stats_.identities;
            return cond != 0.0f ? args[1] : args[2];
        }
        if (args[1] == args[2]) {
            ++stats_.identities;
            return args[1];
        }
    }
    auto key = std::make_tuple(op, imm, args);
    if (op != Op::Bake && op != Op::Dynamic) {
        auto it = shared_.find(key);
        if (it != shared_.end()) {
            ++stats_.shared;
            return it->second;
        }
    }
    Inst inst;
    inst.op = op;
    inst.nargs = static_cast<uint8_t>(args.size());
    inst.nout = static_cast<uint8_t>(nout);
    inst.imm = imm;
    inst.firstArg = static_cast<int32_t>(program_.args.size());
    inst.result = program_.valueCount;
    inst.line = line_;
    inst.column = column_;
    program_.args.insert(program_.args.end(), args.begin(), args.end());
    program_.valueCount += nout;
    program_.insts.push_back(inst);
    constOf_.resize(static_cast<size_t>(program_.valueCount), -1);
    shared_[key] = inst.result;
    return inst.result;
}

}  // namespace mpshade
