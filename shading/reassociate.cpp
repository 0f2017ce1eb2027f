#include "shading/reassociate.h"

#include <algorithm>

#include "geometry/error.h"
#include "shading/ir_builder.h"

namespace mpshade {
namespace {

struct Term {
    int32_t value;  // in the old program
    bool negative;
};

class Reassociator {
  public:
    Reassociator(const IrProgram& program, const BindingTimes& times)
        : old_(program), times_(times), builder_(out_) {
        const size_t n = static_cast<size_t>(program.valueCount);
        defining_ = definingInstructions(program);
        uses_.assign(n, 0);
        for (size_t k = 0; k < program.insts.size(); ++k) {
            const Inst& inst = program.insts[k];
            for (int a = 0; a < inst.nargs; ++a)
                ++uses_[static_cast<size_t>(program.argsOf(inst)[a])];
        }
        for (int v : program.ci)
            if (v >= 0) ++uses_[static_cast<size_t>(v)];
        for (int v : program.oi)
            if (v >= 0) ++uses_[static_cast<size_t>(v)];
        for (int v : program.channelOutputs) ++uses_[static_cast<size_t>(v)];
    }

    IrProgram run() {
        out_ = old_.emptyCopy();
        map_.assign(static_cast<size_t>(old_.valueCount), -1);
        for (const Inst& inst : old_.insts) {
            builder_.setLocation(inst.line, inst.column);
            const int32_t* args = old_.argsOf(inst);
            int result;
            if (inst.op == Op::Const) {
                result = builder_.constant(inst.constant);
            } else if (!regroup(inst, result)) {
                std::vector<int> mapped;
                for (int a = 0; a < inst.nargs; ++a)
                    mapped.push_back(map_[static_cast<size_t>(args[a])]);
                result = builder_.emit(inst.op, mapped, inst.nout, inst.imm);
            }
            for (int o = 0; o < inst.nout; ++o) {
                map_[static_cast<size_t>(inst.result + o)] = result + o;
                describe(inst.result + o, result + o);
            }
        }
        for (int k = 0; k < 3; ++k) {
            if (old_.ci[k] >= 0) out_.ci[k] = map_[static_cast<size_t>(old_.ci[k])];
            if (old_.oi[k] >= 0) out_.oi[k] = map_[static_cast<size_t>(old_.oi[k])];
        }
        for (int v : old_.channelOutputs)
            out_.channelOutputs.push_back(map_[static_cast<size_t>(v)]);
        eliminateDeadCode(out_);
        return std::move(out_);
    }

  private:
    Stage stage(int32_t v) const { return times_.stage[static_cast<size_t>(v)]; }

    void describe(int32_t oldValue, int32_t newValue) {
        if (static_cast<size_t>(oldValue) >= old_.info.size()) return;
        out_.info.resize(static_cast<size_t>(out_.valueCount));
        ValueInfo& info = out_.info[static_cast<size_t>(newValue)];
        if (info.name.empty() && info.component < 0)
            info = old_.info[static_cast<size_t>(oldValue)];
    }

    // Leaves of the sum (or product) rooted at v: interior nodes are dynamic sums used
    // only here, so regrouping them duplicates nothing. A product also opens static
    // products used only here, so its constant factors come apart from the others: a
    // colour constant times fbm times a noise, times a dynamic term, is per component
    // (c_k fbm a) d, three static values, where fbm a is one value shared by the three.
    void flatten(int32_t v, bool negative, bool root, bool product,
                 std::vector<Term>& terms) const {
        const int k = defining_[static_cast<size_t>(v)];
        const Inst& inst = old_.insts[static_cast<size_t>(k)];
        const bool chain =
            product ? inst.op == Op::Mul : (inst.op == Op::Add || inst.op == Op::Sub);
        const bool opens = stage(v) == Stage::Dynamic || (product && stage(v) == Stage::Static);
        if (chain && opens && (root || uses_[static_cast<size_t>(v)] == 1)) {
            const int32_t* args = old_.argsOf(inst);
            flatten(args[0], negative, false, product, terms);
            flatten(args[1], inst.op == Op::Sub ? !negative : negative, false, product, terms);
            return;
        }
        terms.push_back({v, negative});
    }

    int combine(const std::vector<Term>& terms, bool product) {
        int acc = -1;
        for (const Term& t : terms) {
            const int v = map_[static_cast<size_t>(t.value)];
            if (acc < 0) {
                acc = t.negative ? builder_.emit(Op::Neg, {v}) : v;
            } else if (product) {
                acc = builder_.emit(Op::Mul, {acc, v});
            } else {
                acc = builder_.emit(t.negative ? Op::Sub : Op::Add, {acc, v});
            }
        }
        return acc;
    }

    bool regroup(const Inst& inst, int& result) {
        const bool product = inst.op == Op::Mul;
        if (!(product || inst.op == Op::Add || inst.op == Op::Sub)) return false;
        if (stage(inst.result) != Stage::Dynamic) return false;
        std::vector<Term> terms, fixed, constants, varying;
        flatten(inst.result, false, true, product, terms);
        for (const Term& t : terms) {
            float unused;
            if (product && builder_.constantValue(map_[static_cast<size_t>(t.value)], unused))
                constants.push_back(t);
            else
                (stage(t.value) == Stage::Dynamic ? varying : fixed).push_back(t);
        }
        if (varying.empty() || fixed.empty() || fixed.size() + constants.size() < 2) return false;
        // All the static terms first, as one static value (in the order of the old
        // program's values, so the same factors make the same value); then the constant
        // factors of a product; then the dynamic terms.
        std::sort(fixed.begin(), fixed.end(),
                  [](const Term& a, const Term& b) { return a.value < b.value; });
        fixed.insert(fixed.end(), constants.begin(), constants.end());
        int acc = combine(fixed, product);
        for (const Term& t : varying) {
            const int v = map_[static_cast<size_t>(t.value)];
            acc = builder_.emit(product ? Op::Mul : (t.negative ? Op::Sub : Op::Add), {acc, v});
        }
        result = acc;
        return true;
    }

    const IrProgram& old_;
    const BindingTimes& times_;
    IrProgram out_;
    IrBuilder builder_;
    std::vector<int> defining_, uses_;
    std::vector<int32_t> map_;
};

}  // namespace

IrProgram reassociate(const IrProgram& program, const BindingTimes& times) {
    return Reassociator(program, times).run();
}

}  // namespace mpshade
