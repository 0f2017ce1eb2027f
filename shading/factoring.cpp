#include "shading/factoring.h"

#include <algorithm>
#include <map>
#include <set>

#include "geometry/error.h"
#include "shading/lower.h"
#include "shading/min_cut.h"
#include "shading/reassociate.h"

namespace mpshade {

int instructionCount(const IrProgram& program) {
    int n = 0;
    for (const Inst& inst : program.insts) n += inst.op != Op::Const;
    return n;
}

int programCost(const IrProgram& program) {
    int cost = 0;
    for (const Inst& inst : program.insts) cost += opCost(inst.op, inst.imm);
    return cost;
}

namespace {

// Static values that a dynamic instruction reads, or that are outputs themselves.
std::vector<char> boundary(const IrProgram& p, const BindingTimes& bt) {
    std::vector<char> b(static_cast<size_t>(p.valueCount), 0);
    for (const Inst& inst : p.insts) {
        if (bt.stage[static_cast<size_t>(inst.result)] != Stage::Dynamic) continue;
        for (int a = 0; a < inst.nargs; ++a) {
            const int32_t v = p.argsOf(inst)[a];
            if (bt.stage[static_cast<size_t>(v)] == Stage::Static) b[static_cast<size_t>(v)] = 1;
        }
    }
    for (int v : p.ci)
        if (bt.stage[static_cast<size_t>(v)] == Stage::Static) b[static_cast<size_t>(v)] = 1;
    for (int v : p.oi)
        if (bt.stage[static_cast<size_t>(v)] == Stage::Static) b[static_cast<size_t>(v)] = 1;
    return b;
}

// The minimum vertex cut: node 2v is v's input side, 2v + 1 its output side.
std::vector<int32_t> chooseChannels(const IrProgram& p, const BindingTimes& bt,
                                    const FactorOptions& options) {
    const size_t n = static_cast<size_t>(p.valueCount);
    const std::vector<int> defining = definingInstructions(p);
    const std::vector<char> needed = boundary(p, bt);
    FlowGraph g;
    for (size_t v = 0; v < 2 * n; ++v) g.addNode();
    const int s = g.addNode(), t = g.addNode();
    for (size_t v = 0; v < n; ++v) {
        if (bt.stage[v] != Stage::Static) continue;
        const Inst& inst = p.insts[static_cast<size_t>(defining[v])];
        const int in = static_cast<int>(2 * v), out = in + 1;
        g.addEdge(in, out, 1);  // storing v costs one float
        // Work the dynamic part must not repeat is anchored to the static side.
        bool anchored = !mayRecompute(inst.op, inst.imm, options) || inst.op == Op::Bake ||
                        inst.op == Op::Global || inst.op == Op::Diffuse ||
                        inst.op == Op::Specular || inst.op == Op::Phong;
        for (int a = 0; a < inst.nargs; ++a) {
            const size_t arg = static_cast<size_t>(p.argsOf(inst)[a]);
            if (bt.stage[arg] == Stage::Static)
                g.addEdge(static_cast<int>(2 * arg + 1), in, FlowGraph::kInfinite);
            if (bt.stage[arg] == Stage::Dynamic)
                anchored = true;  // under bake(): only the static phase can
        }
        if (anchored) g.addEdge(s, in, FlowGraph::kInfinite);
        if (needed[v]) g.addEdge(out, t, FlowGraph::kInfinite);
    }
    g.maxFlow(s, t);
    const std::vector<char> reaches = g.reachesSink(t);
    std::vector<int32_t> cut;
    for (size_t v = 0; v < n; ++v)
        if (bt.stage[v] == Stage::Static && !reaches[2 * v] && reaches[2 * v + 1])
            cut.push_back(static_cast<int32_t>(v));
    return cut;
}

IrProgram staticPartOf(const IrProgram& p, const std::vector<int32_t>& channels) {
    IrProgram s = p;
    for (int k = 0; k < 3; ++k) s.ci[k] = s.oi[k] = -1;
    s.channelOutputs = channels;
    eliminateDeadCode(s);
    return s;
}

IrProgram dynamicPartOf(const IrProgram& p, const std::vector<int32_t>& channels) {
    std::map<int32_t, int> channelOf;
    for (size_t k = 0; k < channels.size(); ++k) channelOf[channels[k]] = static_cast<int>(k);
    IrProgram d = p.emptyCopy();
    d.channelInputs = static_cast<int>(channels.size());
    std::vector<int32_t> map(static_cast<size_t>(p.valueCount), -1);
    auto define = [&](const Inst& from, Op op, int nargs, int nout, int imm,
                      const std::vector<int32_t>& args) {
        Inst inst = from;
        inst.op = op;
        inst.nargs = static_cast<uint8_t>(nargs);
        inst.nout = static_cast<uint8_t>(nout);
        inst.imm = imm;
        inst.firstArg = static_cast<int32_t>(d.args.size());
        inst.result = d.valueCount;
        d.args.insert(d.args.end(), args.begin(), args.end());
        d.valueCount += nout;
        d.insts.push_back(inst);
        return inst.result;
    };
    for (const Inst& inst : p.insts) {
        std::vector<int32_t> args;
        for (int a = 0; a < inst.nargs; ++a)
            args.push_back(map[static_cast<size_t>(p.argsOf(inst)[a])]);
        // Outputs that are channels are read from the n-tuple; the rest are computed (and
        // removed below when nothing dynamic needs them).
        bool allChannels = true;
        for (int o = 0; o < inst.nout; ++o)
            allChannels = allChannels && channelOf.count(inst.result + o);
        if (!allChannels) {
            bool computable = true;
            for (int32_t a : args) computable = computable && a >= 0;
            if (computable) {
                const int first = define(inst, inst.op, inst.nargs, inst.nout, inst.imm, args);
                for (int o = 0; o < inst.nout; ++o)
                    map[static_cast<size_t>(inst.result + o)] = first + o;
                d.insts.back().constant = inst.constant;
            }
        }
        for (int o = 0; o < inst.nout; ++o) {
            auto it = channelOf.find(inst.result + o);
            if (it != channelOf.end())
                map[static_cast<size_t>(inst.result + o)] =
                    define(inst, Op::Channel, 0, 1, it->second, {});
        }
    }
    for (int k = 0; k < 3; ++k) {
        d.ci[k] = map[static_cast<size_t>(p.ci[k])];
        d.oi[k] = map[static_cast<size_t>(p.oi[k])];
        MPSHADE_CHECK(d.ci[k] >= 0 && d.oi[k] >= 0);
    }
    d.info.resize(static_cast<size_t>(d.valueCount));
    for (size_t v = 0; v < map.size() && v < p.info.size(); ++v)
        if (map[v] >= 0) d.info[static_cast<size_t>(map[v])] = p.info[v];
    eliminateDeadCode(d);
    // Everything the dynamic part computes must be dynamic, free, or cheap static work.
    return d;
}

// Work a shader map exists for, however few cost units it counts: occlusion rays and bake()
// only the static phase may do; noise patterns cost tens of nanoseconds a point (opCost's
// 40 units underrate them against arithmetic and lighting) and alias when point-sampled.
bool staticPhaseWork(Op op) {
    switch (op) {
        case Op::Occlusion:
        case Op::Bake:
        case Op::Noise:
        case Op::Snoise:
        case Op::Cellnoise:
        case Op::Fbm:
        case Op::Turbulence:
            return true;
        default:
            return false;
    }
}

// The channels of `cut` cheaper to repeat per shading point than to read back
// (FactorOptions::storeAboveCost): each one's own static work (what computing it alone
// takes) holds no staticPhaseWork() and nothing that would alias if point-sampled, and
// together they cost at most the limit (or each adds no more than cheap arithmetic to the
// rest). Cheapest first, so a channel that shares a lighting call with others (the three
// of a diffuse colour) goes with them. `cost` receives the static work they take together.
std::vector<int32_t> notWorthStoring(const IrProgram& p, const std::vector<int32_t>& cut,
                                     const FactorOptions& options, int& cost) {
    cost = 0;
    std::vector<std::pair<int, int32_t>> candidates;
    // Each candidate costs a pass over the program: an n-tuple this wide is no cheap
    // shader, and the passes stay linear in practice.
    if (cut.size() > 256) return {};
    for (int32_t v : cut) {
        const IrProgram alone = staticPartOf(p, {v});
        const int own = programCost(alone);
        if (own > options.storeAboveCost) continue;
        bool clean = true;
        for (const Inst& inst : alone.insts)
            clean = clean && !staticPhaseWork(inst.op) && !isDiscontinuous(inst.op);
        if (clean) candidates.emplace_back(own, v);
    }
    std::stable_sort(candidates.begin(), candidates.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<int32_t> chosen;
    for (const auto& candidate : candidates) {
        chosen.push_back(candidate.second);
        const int with = programCost(staticPartOf(p, chosen));
        // Within the limit, or next to free: once the dynamic part repeats the lighting, a
        // channel that is one add away from it costs that add (as the cut itself allows).
        if (with <= options.storeAboveCost || with - cost <= options.recomputeCostLimit)
            cost = with;
        else
            chosen.pop_back();
    }
    return chosen;
}

std::string describeValue(const IrProgram& p, int32_t v) {
    const ValueInfo* info =
        static_cast<size_t>(v) < p.info.size() ? &p.info[static_cast<size_t>(v)] : nullptr;
    if (info && !info->name.empty()) return "'" + info->name + "'";
    return "";
}

// Per value: whether the frames compute it -- reached from Ci and Oi without passing through
// a bake(), whose argument the static phase computes once, its dynamic inputs frozen.
std::vector<char> computedPerFrame(const IrProgram& p, const std::vector<int>& defining) {
    std::vector<char> reached(defining.size(), 0);
    std::vector<int32_t> stack;
    for (int k = 0; k < 3; ++k) stack.push_back(p.ci[k]), stack.push_back(p.oi[k]);
    while (!stack.empty()) {
        const int32_t v = stack.back();
        stack.pop_back();
        if (v < 0 || reached[static_cast<size_t>(v)]) continue;
        reached[static_cast<size_t>(v)] = 1;
        const int d = defining[static_cast<size_t>(v)];
        if (d < 0) continue;
        const Inst& inst = p.insts[static_cast<size_t>(d)];
        if (inst.op == Op::Bake) continue;
        for (int a = 0; a < inst.nargs; ++a) stack.push_back(p.argsOf(inst)[a]);
    }
    return reached;
}

// Where a dynamic input enters: its instruction, or for work a dynamic() forced, the
// dynamic() the author wrote.
const Inst& sourceOf(const IrProgram& p, const BindingTimes& bt, const std::vector<int>& defining,
                     int32_t v) {
    const int32_t by = bt.forcedBy[static_cast<size_t>(v)];
    return p.insts[static_cast<size_t>(by >= 0 ? by : defining[static_cast<size_t>(v)])];
}

// The steps from value `at` back to the dynamic input that reached it, each line once.
std::vector<std::string> causeChain(const IrProgram& p, const BindingTimes& bt,
                                    const std::vector<int>& defining, int32_t at) {
    std::vector<std::string> chain;
    int lastLine = -1;
    for (int guard = 0; at >= 0 && guard < 64; ++guard) {
        const Inst& def = p.insts[static_cast<size_t>(defining[static_cast<size_t>(at)])];
        const int32_t cause = bt.cause[static_cast<size_t>(at)];
        if (cause < 0) {
            const Inst& where = sourceOf(p, bt, defining, at);
            chain.push_back(bt.why[static_cast<size_t>(at)] + " (line " +
                            std::to_string(where.line) + ":" + std::to_string(where.column) + ")");
            break;
        }
        if (def.line != lastLine) {
            const std::string name = describeValue(p, at);
            chain.push_back(std::string(opName(def.op)) + (name.empty() ? "" : " -> " + name) +
                            " at line " + std::to_string(def.line) + ":" +
                            std::to_string(def.column));
            lastLine = def.line;
        }
        at = cause;
    }
    return chain;
}

// Every dynamic input that reaches the values `from`, through dynamic values (not into a
// bake's argument, which the static phase computes), in the order first met.
std::vector<DynamicCause> causesOf(const IrProgram& p, const BindingTimes& bt,
                                   const std::vector<int>& defining,
                                   const std::vector<int32_t>& from) {
    std::vector<DynamicCause> causes;
    auto add = [&](DynamicCause c) {
        for (const DynamicCause& k : causes)
            if (k.kind == c.kind && k.name == c.name && k.index == c.index) return;
        causes.push_back(std::move(c));
    };
    std::vector<char> seen(defining.size(), 0);
    std::vector<int32_t> stack(from.rbegin(), from.rend());
    while (!stack.empty()) {
        const int32_t v = stack.back();
        stack.pop_back();
        const size_t u = static_cast<size_t>(v);
        if (v < 0 || seen[u] || bt.stage[u] != Stage::Dynamic) continue;
        seen[u] = 1;
        const Inst& inst = p.insts[static_cast<size_t>(defining[u])];
        DynamicCause c;
        const Inst& where = sourceOf(p, bt, defining, v);
        c.line = where.line, c.column = where.column;
        c.why = bt.why[u];
        const bool source = bt.cause[u] < 0;
        if (bt.lightMoves[u]) {
            c.kind = "light", c.index = inst.imm;
            c.why = "light " + std::to_string(inst.imm) + " moves relative to the object";
            add(c);
        } else if (source && inst.op == Op::Global) {
            const auto id = static_cast<GlobalId>(inst.imm);
            c.kind = id == GlobalId::time ? "time" : "view";
            c.name = globalName(id);
            add(c);
        } else if (source && inst.op == Op::Param) {
            c.kind = "parameter";
            for (const AnimatedParam& ap : p.animatedParams)
                if (ap.slot <= inst.imm && inst.imm < ap.slot + ap.components) c.name = ap.name;
            add(c);
        } else if (source && inst.op == Op::LightAmbient) {
            c.kind = "ambient_light", c.index = inst.imm;
            add(c);
        } else if (source) {
            // dynamic() in the source, or a binding's repeat (imm k + 1, lower.cpp), on this
            // value or on the value the static work under it feeds.
            const int32_t by = inst.op == Op::Dynamic ? defining[u] : bt.forcedBy[u];
            const bool repeat = by >= 0 && p.insts[static_cast<size_t>(by)].op == Op::Dynamic &&
                                p.insts[static_cast<size_t>(by)].imm > 0;
            c.kind = repeat ? "override" : "annotation";
            add(c);
        }
        if (inst.op == Op::Bake) continue;
        for (int a = inst.nargs - 1; a >= 0; --a) stack.push_back(p.argsOf(inst)[a]);
    }
    return causes;
}

// Per value: whether it is written inside a bake() on its own line. Shared with work the
// frames do (the -I of a baked rim term and of a specular), it is still that line's baked
// work: the per-frame use is reported where it is.
std::vector<char> writtenInBake(const IrProgram& p, const std::vector<int>& defining) {
    std::vector<char> inBake(defining.size(), 0);
    std::vector<int32_t> stack;
    for (const Inst& bake : p.insts) {
        if (bake.op != Op::Bake) continue;
        for (int a = 0; a < bake.nargs; ++a) stack.push_back(p.argsOf(bake)[a]);
        while (!stack.empty()) {
            const int32_t v = stack.back();
            stack.pop_back();
            const int d = v < 0 ? -1 : defining[static_cast<size_t>(v)];
            if (d < 0 || inBake[static_cast<size_t>(v)]) continue;
            const Inst& inst = p.insts[static_cast<size_t>(d)];
            if (inst.line != bake.line) continue;
            inBake[static_cast<size_t>(v)] = 1;
            for (int a = 0; a < inst.nargs; ++a) stack.push_back(p.argsOf(inst)[a]);
        }
    }
    return inBake;
}

// Where each value's work runs, as the reports need it (computed once per factoring).
struct WorkPlaces {
    std::vector<int> defining;   // definingInstructions
    std::vector<char> perFrame;  // computedPerFrame
    std::vector<char> inBake;    // writtenInBake
    // Dynamic work the frames do themselves: reached per frame and not a bake's own line.
    bool repeated(size_t v) const { return perFrame[v] && !inBake[v]; }
};

WorkPlaces workPlacesOf(const IrProgram& p) {
    WorkPlaces w;
    w.defining = definingInstructions(p);
    w.perFrame = computedPerFrame(p, w.defining);
    w.inBake = writtenInBake(p, w.defining);
    return w;
}

// Lines whose bake() freezes a dynamic input (the view, time, an animated parameter or a
// moving light): the static phase computes them once, at its representative values.
std::vector<DynamicLine> explainBakedLines(const IrProgram& p, const BindingTimes& bt,
                                           const WorkPlaces& places) {
    const std::vector<int>& defining = places.defining;
    std::map<int, DynamicLine> lines;
    for (const Inst& inst : p.insts) {
        if (inst.op != Op::Bake || inst.nargs < 1 || lines.count(inst.line)) continue;
        const int32_t arg = p.argsOf(inst)[0];
        if (bt.stage[static_cast<size_t>(arg)] != Stage::Dynamic) continue;
        lines[inst.line] = {inst.line, causeChain(p, bt, defining, arg),
                            causesOf(p, bt, defining, {arg})};
    }
    std::vector<DynamicLine> out;
    for (auto& [l, line] : lines) out.push_back(std::move(line));
    return out;
}

// Whether an expression is made of literals alone (so constant for every binding).
bool literalOnly(const Expr& e) {
    if (e.kind == Expr::Kind::Name) return false;
    for (const auto& a : e.args)
        if (!literalOnly(*a)) return false;
    return true;
}

// A warning at a source position.
struct Warning {
    int line = 0, column = 0;
    std::string text;
};

void lintExpr(const Expr& e, std::vector<Warning>& out) {
    if (e.kind == Expr::Kind::Call && e.name == "dynamic" && !e.args.empty() &&
        literalOnly(*e.args[0]))
        out.push_back({e.line, e.column,
                       "dynamic() of a constant does nothing: a constant is never repeated"});
    for (const auto& a : e.args) lintExpr(*a, out);
}

void lintStmt(const Stmt& s, std::vector<Warning>& out) {
    for (const Expr* e : {s.value.get(), s.target.get()})
        if (e) lintExpr(*e, out);
    for (const Stmt* t : {s.init.get(), s.step.get()})
        if (t) lintStmt(*t, out);
    for (const auto& t : s.body) lintStmt(*t, out);
    for (const auto& t : s.elseBody) lintStmt(*t, out);
}

// Annotations that do nothing: a dynamic() of literals (the lowering folds it away), and a
// bake() whose value is already static or free for this binding.
std::vector<std::string> lintAnnotations(const ShaderAst& ast, const IrProgram& p,
                                         const BindingTimes& bt) {
    std::vector<Warning> found;
    if (ast.body) lintStmt(*ast.body, found);
    std::set<std::pair<int, int>> said;
    for (const Inst& inst : p.insts) {
        // imm > 0: a store the binding asked for, which means to keep a static value.
        if (inst.op != Op::Bake || inst.nargs < 1 || inst.imm > 0) continue;
        if (bt.stage[static_cast<size_t>(p.argsOf(inst)[0])] == Stage::Dynamic) continue;
        if (!said.insert({inst.line, inst.column}).second) continue;
        found.push_back({inst.line, inst.column,
                         "bake() of a value already static for this binding changes nothing "
                         "here (no view, time, animated parameter or moving light reaches it)"});
    }
    std::stable_sort(found.begin(), found.end(), [](const Warning& a, const Warning& b) {
        return std::pair(a.line, a.column) < std::pair(b.line, b.column);
    });
    std::vector<std::string> out;
    for (const Warning& w : found)
        out.push_back(std::to_string(w.line) + ":" + std::to_string(w.column) + ": " + w.text);
    return out;
}

std::vector<SourceLineStages> stagesByLine(const IrProgram& p, const BindingTimes& bt,
                                           const WorkPlaces& places) {
    std::map<int, SourceLineStages> lines;
    for (const Inst& inst : p.insts) {
        // Reading an input (a global, a parameter) is no work of the line's.
        if (inst.line <= 0 || inst.op == Op::Const || inst.op == Op::Global ||
            inst.op == Op::Param || inst.op == Op::LightAmbient)
            continue;
        const size_t v = static_cast<size_t>(inst.result);
        SourceLineStages& l = lines[inst.line];
        l.line = inst.line;
        switch (bt.stage[v]) {
            case Stage::Dynamic:
                if (places.repeated(v))
                    l.repeated = true;
                else
                    l.baked = true;
                break;
            case Stage::Static:
                l.stored = true;
                break;
            case Stage::Free:
                l.free = true;
                break;
        }
    }
    std::vector<SourceLineStages> out;
    for (auto& [n, l] : lines) out.push_back(l);
    return out;
}

std::vector<DynamicLine> explainDynamicLines(const IrProgram& p, const BindingTimes& bt,
                                             const WorkPlaces& places) {
    const std::vector<int>& defining = places.defining;
    std::map<int, DynamicLine> lines;
    for (const Inst& inst : p.insts) {
        const size_t v = static_cast<size_t>(inst.result);
        if (bt.stage[v] != Stage::Dynamic || inst.line <= 0 || lines.count(inst.line)) continue;
        // Only under a bake(): computed in the static phase.
        if (!places.repeated(v)) continue;
        // The inputs themselves (a parameter's declaration, a global) are the chain's end,
        // not a line the author wrote dynamic work on.
        if (inst.op == Op::Global || inst.op == Op::Param || inst.op == Op::LightAmbient) continue;
        DynamicLine line;
        line.line = inst.line;
        line.chain = causeChain(p, bt, defining, static_cast<int32_t>(v));
        lines[inst.line] = line;
    }
    // Every input of each line: from all the line's dynamic work the frames do.
    std::map<int, std::vector<int32_t>> work;
    for (const Inst& inst : p.insts) {
        const size_t v = static_cast<size_t>(inst.result);
        if (lines.count(inst.line) && bt.stage[v] == Stage::Dynamic && places.repeated(v))
            for (int o = 0; o < inst.nout; ++o) work[inst.line].push_back(inst.result + o);
    }
    for (auto& [l, line] : lines) line.causes = causesOf(p, bt, defining, work[l]);
    std::vector<DynamicLine> out;
    for (auto& [l, line] : lines) out.push_back(std::move(line));
    return out;
}

}  // namespace

// The binding's factoring overrides, checked against the analysis: a value can be stored
// only if nothing dynamic reaches it (else it would be frozen: that is bake()'s, in the
// source), and repeated only if it is static work (free work is never stored; a constant
// has nothing to repeat).
void checkOverrides(const ShaderAst& ast, const ShaderBinding& binding, const IrProgram& p,
                    const BindingTimes& bt) {
    const std::vector<int> defining = definingInstructions(p);
    for (size_t k = 0; k < binding.overrides.size(); ++k) {
        const FactoringOverride& o = binding.overrides[k];
        const std::string what = "'" + o.spelled + "'";
        bool found = false;
        for (const Inst& inst : p.insts) {
            if ((inst.op != Op::Bake && inst.op != Op::Dynamic) ||
                inst.imm != static_cast<int>(k) + 1 || inst.nargs < 1)
                continue;
            found = true;
            const int32_t arg = p.argsOf(inst)[0];
            const Stage stage = bt.stage[static_cast<size_t>(arg)];
            auto fail = [&](const std::string& why) {
                throw InputError({ast.file, inst.line, inst.column, {}}, why);
            };
            if (o.kind == FactoringOverride::Kind::Store && stage == Stage::Dynamic) {
                std::string causes;
                for (const DynamicCause& c : causesOf(p, bt, defining, {arg}))
                    causes += (causes.empty() ? "" : "; ") + c.why;
                fail("cannot store " + what + ": " + causes +
                     " (bake() in the source would freeze it at the static run's values)");
            }
            if (o.kind == FactoringOverride::Kind::Repeat && stage == Stage::Free)
                fail("cannot repeat " + what +
                     ": it is free work on the frames' geometry, never stored, so it is "
                     "repeated already");
        }
        if (!found)
            throw InputError({ast.file, o.line, o.column, {}},
                             what + " is a constant for this binding: nothing to store or repeat");
    }
}

FactoredShader factorShader(const ShaderAst& ast, const ShaderBinding& binding,
                            const FactorOptions& options) {
    FactoredShader f;
    const IrProgram lowered = lowerShader(ast, binding);
    const BindingTimes loweredTimes = analyzeBindingTimes(lowered, binding, options);
    checkOverrides(ast, binding, lowered, loweredTimes);
    const std::vector<char> naive = boundary(lowered, loweredTimes);
    f.naiveWidth = static_cast<int>(std::count(naive.begin(), naive.end(), 1));
    f.analyzed = options.reassociate ? reassociate(lowered, loweredTimes) : lowered;
    f.times = analyzeBindingTimes(f.analyzed, binding, options);

    std::vector<int32_t> cut = chooseChannels(f.analyzed, f.times, options);
    const std::vector<int32_t> repeated =
        notWorthStoring(f.analyzed, cut, options, f.recomputedStaticCost);
    std::erase_if(cut, [&](int32_t v) {
        return std::find(repeated.begin(), repeated.end(), v) != repeated.end();
    });
    f.staticPart = staticPartOf(f.analyzed, cut);
    f.dynamicPart = dynamicPartOf(f.analyzed, cut);
    const WorkPlaces places = workPlacesOf(f.analyzed);
    const std::vector<int>& defining = places.defining;
    for (int32_t v : cut) {
        const Inst& inst = f.analyzed.insts[static_cast<size_t>(defining[static_cast<size_t>(v)])];
        ChannelInfo c;
        if (static_cast<size_t>(v) < f.analyzed.info.size()) {
            const ValueInfo& info = f.analyzed.info[static_cast<size_t>(v)];
            c.name = info.name;
            c.type = info.type;
            c.component = info.component;
        }
        c.line = inst.line;
        c.column = inst.column;
        c.op = inst.op;
        f.channels.push_back(c);
    }
    f.chosenWidth = static_cast<int>(cut.size());
    f.originalInstructions = instructionCount(lowered);
    f.staticInstructions = instructionCount(f.staticPart);
    f.dynamicInstructions = instructionCount(f.dynamicPart);
    f.originalCost = programCost(lowered);
    f.staticCost = programCost(f.staticPart);
    f.dynamicCost = programCost(f.dynamicPart);
    f.dynamicLines = explainDynamicLines(f.analyzed, f.times, places);
    f.bakedLines = explainBakedLines(f.analyzed, f.times, places);
    f.lineStages = stagesByLine(f.analyzed, f.times, places);
    f.warnings = lintAnnotations(ast, f.analyzed, f.times);
    return f;
}

}  // namespace mpshade
