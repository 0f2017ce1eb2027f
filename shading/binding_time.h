// binding_time.h -- binding-time analysis: which values of a shader, specialized to one
// object's binding, change from frame to frame (the patent's S_d) and which are fixed
// over the range of control values (S_s).
#pragma once

#include <string>
#include <vector>

#include "shading/binding.h"
#include "shading/ir.h"

namespace mpshade {

enum class Stage : uint8_t {
    Free,     // constants, and geometry the dynamic phase has anyway: never stored
    Static,   // fixed over the range: computed in the static phase
    Dynamic,  // changes per frame instance: computed in the dynamic phase
};

struct FactorOptions {
    // The dynamic phase interpolates P, N, Ng, dPdu, dPdv, u, v, s, t from the geometry, so
    // they (and cheap arithmetic on them alone) need no storage. Off: they are static
    // inputs like any other, and what the dynamic part needs of them is stored.
    bool geometryInDynamicPhase = true;
    // The dynamic part may repeat static work instead of reading it from the n-tuple, but
    // only operations whose cost (opCost) is at most this: arithmetic, not noise, lighting
    // or occlusion.
    int recomputeCostLimit = 2;
    // Nor discontinuous operations (step, floor, fract, comparisons, select...): stored,
    // their edges are prefiltered with the rest of the n-tuple (a shader map's levels and
    // probe footprint, or interpolation between facet vertices); repeated per shading point
    // they would be point-sampled, and alias (a brick's mortar lines computed from s and t).
    bool storeDiscontinuities = true;
    // Regroup sums and products so their static terms form one stored value (the patent's
    // C = A1 + A2 + A3 Kspec stores A1 + A2 and A3).
    bool reassociate = true;
    // A static part whose whole cost (opCost units, per point) is at most this, with no
    // occlusion, bake() or discontinuous operation in it, is not stored at all: the
    // dynamic part runs the whole shader on the interpolated geometry. Reading an n-tuple
    // costs a probe per point (20-60 ns on 2 cores, memory bound) plus the fills and the
    // memory of a map, where 64 units run in about 10 ns (a diffuse() is 30; the
    // interpreter's figures in docs/factoring.md). 0: always store what is static.
    int storeAboveCost = 64;
};

// A rough per-lane cost of an operation, in units of one float add.
int opCost(Op op, int imm = 0);

// Whether an operation's result can jump where its arguments change smoothly.
bool isDiscontinuous(Op op);

// Whether the dynamic part may repeat an operation whose arguments it has, rather than
// read its result from the n-tuple.
bool mayRecompute(Op op, int imm, const FactorOptions& options);

struct BindingTimes {
    std::vector<Stage> stage;  // per value
    std::vector<int32_t>
        cause;  // per dynamic value: the argument that made it dynamic; -1 at a source
    std::vector<std::string>
        why;  // per dynamic source value: what varies ("I (the view direction)")
};

// `binding` says which lights move relative to the object (animated parameters are
// already Param instructions after lowering).
BindingTimes analyzeBindingTimes(const IrProgram& program, const ShaderBinding& binding,
                                 const FactorOptions& options);

}  // namespace mpshade
