// reassociate.h -- regroups sums and products so the static terms of a dynamic sum or
// product are combined first, into one value the n-tuple can store (the patent's
// C = A1 + A2 + A3 Kspec: store A1 + A2 and A3, not A1, A2 and A3). Reassociation
// changes float rounding, within the factoring's tolerance of 1e-5 relative.
#pragma once

#include "shading/binding_time.h"
#include "shading/ir.h"

namespace mpshade {

// `times` is the analysis of `program`. Returns an equivalent program (folded, shared,
// dead code removed); run the analysis again on it.
IrProgram reassociate(const IrProgram& program, const BindingTimes& times);

}  // namespace mpshade
