// ir_builder.h -- appends instructions to an IrProgram, folding constants, applying
// algebraic identities that cannot change a result (x + 0, x * 1, select on a constant) and
// sharing common subexpressions. Each rewrite is counted by kind so `--dump` can say what
// it did (after OSL's constfold, which records a reason for each fold).
#pragma once

#include <map>
#include <tuple>
#include <vector>

#include "shading/ir.h"

namespace mpshade {

struct FoldStats {
    int folded = 0;      // pure operations on constants, replaced by their value
    int identities = 0;  // x + 0, x - 0, x * 1, x / 1, select(c, a, a), select(const, a, b)
    int shared = 0;      // common subexpressions reused
};

class IrBuilder {
  public:
    explicit IrBuilder(IrProgram& program) : program_(program) {}

    void setLocation(int line, int column) {
        line_ = line;
        column_ = column;
    }

    int constant(float value);
    // Returns the first of `nout` result values.
    int emit(Op op, const std::vector<int>& args, int nout = 1, int imm = 0);
    bool constantValue(int value, float& out) const;
    const FoldStats& stats() const { return stats_; }

  private:
    IrProgram& program_;
    int line_ = 0, column_ = 0;
    FoldStats stats_;
    std::vector<int> constOf_;  // value -> index into constValues_, or -1
    std::vector<float> constValues_;
    std::map<uint32_t, int> constants_;  // float bits -> value
    std::map<std::tuple<Op, int, std::vector<int>>, int> shared_;
};

}  // namespace mpshade
