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
    // Stored values whose static work costs at most this many opCost units a point, with
    // no occlusion, bake(), noise or discontinuity in it, are not stored: the dynamic part
    // repeats that work on the interpolated geometry (all of the static part, when every
    // value qualifies: then no map is made). Reading a value back costs a probe per point
    // (20-60 ns, memory bound) plus the fills and the memory of a map, where lighting and
    // arithmetic run at about 0.16 ns a unit (the plastic's 33-unit static part: 5 ns a
    // lane, `mpshade-bench --benchmark_filter=Factored/plastic`): 96 units is three lights'
    // diffuse(). 0: store whatever the cut chooses.
    int storeAboveCost = 96;
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
    // Per value: a light's contribution whose light moves relative to the object -- a cause
    // of its own even where another argument (I, in a specular) made it dynamic first.
    std::vector<uint8_t> lightMoves;
    // Per value: the instruction of the dynamic() that made it dynamic, or -1: a report names
    // the annotation, not the work under it.
    std::vector<int32_t> forcedBy;
};

// `binding` says which lights move relative to the object (animated parameters are
// already Param instructions after lowering).
BindingTimes analyzeBindingTimes(const IrProgram& program, const ShaderBinding& binding,
                                 const FactorOptions& options);

}  // namespace mpshade
