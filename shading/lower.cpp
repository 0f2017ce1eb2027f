#include "shading/lower.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include "geometry/error.h"

namespace mpshade {
namespace {

struct Val {
    ValueType type = ValueType::Void;
    int c[3] = {-1, -1, -1};
    int n() const { return componentCount(type); }
};

class Lowerer {
  public:
    Lowerer(const ShaderAst& ast, const ShaderBinding& binding, const LoweringLimits& limits,
            IrProgram& program)
        : ast_(ast), binding_(binding), limits_(limits), program_(program), b_(program) {}

    void run() {
        program_.shaderName = ast_.name;
        program_.file = ast_.file;
        program_.source = ast_.source;
        scopes_.emplace_back();
        for (const ParamDecl& p : ast_.params) scopes_[0][p.name] = bindParam(p);
        Val ci{ValueType::Color, {}}, oi{ValueType::Color, {}};
        const int zero = b_.constant(0.0f), one = b_.constant(1.0f);
        for (int k = 0; k < 3; ++k) ci.c[k] = zero, oi.c[k] = one;
        scopes_[0]["Ci"] = ci;
        scopes_[0]["Oi"] = oi;
        overrideMatches_.assign(binding_.overrides.size(), 0);
        stmt(*ast_.body);
        for (size_t k = 0; k < binding_.overrides.size(); ++k)
            if (overrideMatches_[k] == 0)
                fail(0, 0,
                     "the factoring override '" + binding_.overrides[k].spelled +
                         "' names nothing in the shader (the line:column of an operation as "
                         "factor reports it, or a variable's name)");
        for (int k = 0; k < 3; ++k) {
            program_.ci[k] = scopes_[0]["Ci"].c[k];
            program_.oi[k] = scopes_[0]["Oi"].c[k];
        }
        eliminateDeadCode(program_);
    }

    const FoldStats& stats() const { return b_.stats(); }

    // The inputs a value depends on, for an error: "time", "P", "parameter 'k' (animated
    // in this scene)", in the order first found.
    std::string inputsReaching(int value) const {
        const std::vector<int> defining = definingInstructions(program_);
        std::vector<std::string> names;
        auto add = [&](const std::string& n) {
            if (std::find(names.begin(), names.end(), n) == names.end()) names.push_back(n);
        };
        std::vector<char> seen(defining.size(), 0);
        std::vector<int> stack = {value};
        while (!stack.empty()) {
            const int v = stack.back();
            stack.pop_back();
            if (v < 0 || static_cast<size_t>(v) >= defining.size() || seen[static_cast<size_t>(v)])
                continue;
            seen[static_cast<size_t>(v)] = 1;
            const int k = defining[static_cast<size_t>(v)];
            if (k < 0) continue;
            const Inst& in = program_.insts[static_cast<size_t>(k)];
            if (in.op == Op::Global) {
                add(globalName(static_cast<GlobalId>(in.imm)));
            } else if (in.op == Op::Param) {
                for (const AnimatedParam& ap : program_.animatedParams)
                    if (ap.slot == in.imm)
                        add("parameter '" + ap.name + "' (animated in this scene)");
            } else if (in.op == Op::LightAmbient) {
                add("ambient light " + std::to_string(in.imm) + " (animated in this scene)");
            } else {
                if (in.op == Op::Diffuse || in.op == Op::Specular || in.op == Op::Phong)
                    add("light " + std::to_string(in.imm));
                const int32_t* args = program_.argsOf(in);
                for (int a = in.nargs - 1; a >= 0; --a) stack.push_back(args[a]);
            }
        }
        std::string out;
        for (size_t i = 0; i < names.size(); ++i)
            out += (i == 0 ? "" : i + 1 == names.size() ? " and " : ", ") + names[i];
        return names.empty() ? "a value that does not fold" : out;
    }

  private:
    [[noreturn]] void fail(int line, int col, const std::string& msg) const {
        throw InputError({ast_.file, line, col, {}}, msg);
    }

    void at(int line, int col) { b_.setLocation(line, col); }

    Val bindParam(const ParamDecl& p) {
        at(p.line, p.column);
        Val v;
        v.type = p.type;
        auto it = binding_.params.find(p.name);
        const ParamBinding::Kind kind =
            it == binding_.params.end() ? ParamBinding::Kind::Default : it->second.kind;
        if (kind == ParamBinding::Kind::Constant) {
            for (int k = 0; k < v.n(); ++k) {
                float value = it->second.value[k];
                if (p.type == ValueType::Int) value = std::trunc(value);
                v.c[k] = b_.constant(value);
            }
        } else if (kind == ParamBinding::Kind::Animated) {
            const int slot = program_.paramFloats;
            program_.animatedParams.push_back({p.name, slot, v.n()});
            program_.paramFloats += v.n();
            const int first = b_.emit(Op::Param, {}, v.n(), slot);
            for (int k = 0; k < v.n(); ++k) v.c[k] = first + k;
        } else {
            v = convert(expr(*p.defaultValue), p.type);
            for (int k = 0; k < v.n(); ++k) {
                float ignored;
                if (!b_.constantValue(v.c[k], ignored))
                    fail(p.defaultValue->line, p.defaultValue->column,
                         "the default of '" + p.name + "' must be a constant");
            }
        }
        return v;
    }

    Val* lookup(const std::string& name) {
        for (auto it = scopes_.rbegin(); it != scopes_.rend(); ++it) {
            auto f = it->find(name);
            if (f != it->end()) return &f->second;
        }
        return nullptr;
    }

    Val scalarVal(int value, ValueType t = ValueType::Float) {
        Val v;
        v.type = t;
        v.c[0] = value;
        return v;
    }

    // Implicit conversions the type checker allowed: int -> float, scalar -> triple.
    Val convert(const Val& v, ValueType to) {
        if (v.type == to) return v;
        Val out;
        out.type = to;
        if (isTriple(to)) {
            for (int k = 0; k < 3; ++k) out.c[k] = isTriple(v.type) ? v.c[k] : v.c[0];
        } else {
            out.c[0] = v.c[0];
        }
        return out;
    }

    Val componentwise(Op op, std::vector<Val> args, ValueType resultType) {
        Val out;
        out.type = resultType;
        for (int k = 0; k < out.n(); ++k) {
            std::vector<int> a;
            for (const Val& v : args) a.push_back(isTriple(v.type) ? v.c[k] : v.c[0]);
            out.c[k] = b_.emit(op, a);
        }
        return out;
    }

    int dot(const Val& a, const Val& b) {
        int s = b_.emit(Op::Mul, {a.c[0], b.c[0]});
        s = b_.emit(Op::Add, {s, b_.emit(Op::Mul, {a.c[1], b.c[1]})});
        return b_.emit(Op::Add, {s, b_.emit(Op::Mul, {a.c[2], b.c[2]})});
    }

    Val global(GlobalId id) {
        Val v;
        v.type = globalType(id);
        const int first = b_.emit(Op::Global, {}, v.n(), static_cast<int>(id));
        for (int k = 0; k < v.n(); ++k) v.c[k] = first + k;
        return v;
    }

    int constantInt(const Expr& e, const char* what, int lo, int hi) {
        Val v = expr(e);
        float value;
        if (!b_.constantValue(v.c[0], value))
            fail(e.line, e.column, std::string(what) + " must be a constant");
        if (value != std::floor(value) || value < lo || value > hi)
            fail(e.line, e.column,
                 std::string(what) + " must be a whole number in [" + std::to_string(lo) + ", " +
                     std::to_string(hi) + "]");
        return static_cast<int>(value);
    }

    // Records what each value is, for reports; the first description of a value wins.
    void describe(const Val& v, const std::string& name = {}) {
        program_.info.resize(static_cast<size_t>(program_.valueCount));
        for (int k = 0; k < v.n(); ++k) {
            ValueInfo& info = program_.info[static_cast<size_t>(v.c[k])];
            if (!name.empty() && info.name.empty())
                info.name = isTriple(v.type) ? name + "[" + std::to_string(k) + "]" : name;
            if (info.component < 0 && info.type == ValueType::Float) {
                info.type = v.type;
                info.component = static_cast<int8_t>(isTriple(v.type) ? k : -1);
            }
        }
    }

    Val expr(const Expr& e) {
        Val v = exprUntagged(e);
        describe(v);
        for (size_t k = 0; k < binding_.overrides.size(); ++k) {
            const FactoringOverride& o = binding_.overrides[k];
            if (o.line == e.line && o.column == e.column) v = overridden(v, k, e.line, e.column);
        }
        return v;
    }

    // v wrapped as a factoring override asks: Bake (store) or Dynamic (repeat), tagged with
    // the override's number + 1 in imm so the factoring can check it is legal.
    Val overridden(Val v, size_t k, int line, int column) {
        ++overrideMatches_[k];
        at(line, column);
        const Op op =
            binding_.overrides[k].kind == FactoringOverride::Kind::Store ? Op::Bake : Op::Dynamic;
        for (int c = 0; c < v.n(); ++c) v.c[c] = b_.emit(op, {v.c[c]}, 1, static_cast<int>(k) + 1);
        return v;
    }

    // Whether a 'repeat' override names bake() call `e`: by its line:column, or by the
    // variable it initializes (unbakeDecl_).
    bool repeatsThisBake(const Expr& e) const {
        if (&e == unbakeDecl_) return true;
        for (const FactoringOverride& o : binding_.overrides)
            if (o.kind == FactoringOverride::Kind::Repeat && o.line == e.line &&
                o.column == e.column)
                return true;
        return false;
    }

    Val exprUntagged(const Expr& e) {
        at(e.line, e.column);
        switch (e.kind) {
            case Expr::Kind::Number:
                return scalarVal(b_.constant(static_cast<float>(e.number)), e.type);
            case Expr::Kind::Name: {
                if (Val* v = lookup(e.name)) return *v;
                GlobalId id;
                ValueType t;
                MPSHADE_CHECK(findGlobal(e.name, id, t));
                return global(id);
            }
            case Expr::Kind::Unary: {
                Val a = expr(*e.args[0]);
                at(e.line, e.column);
                if (e.op == TokenKind::Bang)
                    return scalarVal(b_.emit(Op::Not, {a.c[0]}), ValueType::Int);
                return componentwise(Op::Neg, {a}, a.type);
            }
            case Expr::Kind::Binary:
                return binaryExpr(e);
            case Expr::Kind::Index: {
                Val base = expr(*e.args[0]);
                const int k = constantInt(*e.args[1], "a component index", 0, 2);
                return scalarVal(base.c[k]);
            }
            case Expr::Kind::Call:
                return call(e);
        }
        return {};
    }

    Val binaryExpr(const Expr& e) {
        Val a = expr(*e.args[0]), b = expr(*e.args[1]);
        at(e.line, e.column);
        switch (e.op) {
            case TokenKind::Plus:
                return componentwise(Op::Add, {a, b}, e.type);
            case TokenKind::Minus:
                return componentwise(Op::Sub, {a, b}, e.type);
            case TokenKind::Star:
                return componentwise(Op::Mul, {a, b}, e.type);
            case TokenKind::Slash:
                return componentwise(e.type == ValueType::Int ? Op::IDiv : Op::Div, {a, b}, e.type);
            case TokenKind::Less:
                return scalarVal(b_.emit(Op::Lt, {a.c[0], b.c[0]}), ValueType::Int);
            case TokenKind::LessEq:
                return scalarVal(b_.emit(Op::Le, {a.c[0], b.c[0]}), ValueType::Int);
            case TokenKind::Greater:
                return scalarVal(b_.emit(Op::Gt, {a.c[0], b.c[0]}), ValueType::Int);
            case TokenKind::GreaterEq:
                return scalarVal(b_.emit(Op::Ge, {a.c[0], b.c[0]}), ValueType::Int);
            case TokenKind::AndAnd:
                return scalarVal(b_.emit(Op::And, {a.c[0], b.c[0]}), ValueType::Int);
            case TokenKind::OrOr:
                return scalarVal(b_.emit(Op::Or, {a.c[0], b.c[0]}), ValueType::Int);
            case TokenKind::EqEq:
            case TokenKind::NotEq: {
                int eq = b_.emit(Op::Eq, {a.c[0], b.c[0]});
                if (isTriple(a.type)) {
                    for (int k = 1; k < 3; ++k)
                        eq = b_.emit(Op::And, {eq, b_.emit(Op::Eq, {a.c[k], b.c[k]})});
                }
                if (e.op == TokenKind::NotEq) eq = b_.emit(Op::Not, {eq});
                return scalarVal(eq, ValueType::Int);
            }
            default:
                fail(e.line, e.column, "unexpected operator");
        }
    }

    Val lightSum(Op op, const std::vector<int>& args) {
        Val sum;
        sum.type = ValueType::Color;
        const int zero = b_.constant(0.0f);
        for (int k = 0; k < 3; ++k) sum.c[k] = zero;
        bool first = true;
        for (size_t l = 0; l < binding_.lights.size(); ++l) {
            if (binding_.lights[l].kind == LightKind::Ambient) continue;
            // A distant light does not depend on P: do not make it look as if it did.
            std::vector<int> lightArgs = args;
            if (binding_.lights[l].kind == LightKind::Distant)
                lightArgs[0] = lightArgs[1] = lightArgs[2] = zero;
            const int light = b_.emit(op, lightArgs, 3, static_cast<int>(l));
            // The first light is the sum so far: 0 + x is x but for x = -0 (a light's terms
            // are clamped at +0 and scene colours load -0 as +0; only a colour an animation
            // curve took below 0 can give it, and then a zero either way), and each add cost
            // the dynamic kernel a pass over its lanes.
            for (int k = 0; k < 3; ++k)
                sum.c[k] = first ? light + k : b_.emit(Op::Add, {sum.c[k], light + k});
            first = false;
        }
        return sum;
    }

    // The builtins that apply one operation to each component of their arguments.
    static std::optional<Op> componentwiseOp(Builtin fn) {
        switch (fn) {
            case Builtin::Abs:
                return Op::Abs;
            case Builtin::Floor:
                return Op::Floor;
            case Builtin::Ceil:
                return Op::Ceil;
            case Builtin::Fract:
                return Op::Fract;
            case Builtin::Sqrt:
                return Op::Sqrt;
            case Builtin::Exp:
                return Op::Exp;
            case Builtin::Log:
                return Op::Log;
            case Builtin::Sin:
                return Op::Sin;
            case Builtin::Cos:
                return Op::Cos;
            case Builtin::Tan:
                return Op::Tan;
            case Builtin::Asin:
                return Op::Asin;
            case Builtin::Acos:
                return Op::Acos;
            case Builtin::Atan:
                return Op::Atan;
            case Builtin::Sign:
                return Op::Sign;
            case Builtin::Min:
                return Op::Min;
            case Builtin::Max:
                return Op::Max;
            case Builtin::Mod:
                return Op::Mod;
            case Builtin::Pow:
                return Op::Pow;
            case Builtin::Atan2:
                return Op::Atan2;
            case Builtin::Step:
                return Op::Step;
            case Builtin::Clamp:
                return Op::Clamp;
            case Builtin::Mix:
                return Op::Mix;
            case Builtin::Smoothstep:
                return Op::Smoothstep;
            case Builtin::Bake:
                return Op::Bake;
            case Builtin::Dynamic:
                return Op::Dynamic;
            default:
                return std::nullopt;
        }
    }

    // noise, snoise, cellnoise, fbm and turbulence at p (a float p is (p, 0, 0)); fbm and
    // turbulence take a constant octave count.
    Val noiseCall(Builtin fn, const Expr& e, const Val& p) {
        static const Op kOps[] = {Op::Noise, Op::Snoise, Op::Cellnoise, Op::Fbm, Op::Turbulence};
        const Op op = kOps[static_cast<int>(fn) - static_cast<int>(Builtin::Noise)];
        int octaves = 0;
        if (fn == Builtin::Fbm || fn == Builtin::Turbulence)
            octaves = constantInt(*e.args[1], "the octave count", 1, 16);
        at(e.line, e.column);
        const int zero = b_.constant(0.0f);
        std::vector<int> xyz = isTriple(p.type) ? std::vector<int>{p.c[0], p.c[1], p.c[2]}
                                                : std::vector<int>{p.c[0], zero, zero};
        return scalarVal(b_.emit(op, xyz, 1, octaves));
    }

    // ambient(): the bound ambient lights, those that do not move folded into a constant.
    Val ambientSum() {
        Val sum;
        sum.type = ValueType::Color;
        float folded[3] = {0, 0, 0};
        std::vector<int> animated;
        for (size_t l = 0; l < binding_.lights.size(); ++l) {
            const LightBinding& light = binding_.lights[l];
            if (light.kind != LightKind::Ambient) continue;
            if (light.animated) {
                animated.push_back(b_.emit(Op::LightAmbient, {}, 3, static_cast<int>(l)));
            } else {
                for (int k = 0; k < 3; ++k) folded[k] += light.color[k];
            }
        }
        for (int k = 0; k < 3; ++k) {
            sum.c[k] = b_.constant(folded[k]);
            for (int first : animated) sum.c[k] = b_.emit(Op::Add, {sum.c[k], first + k});
        }
        return sum;
    }

    Val call(const Expr& e) {
        const Builtin fn = findBuiltin(e.name);
        std::vector<Val> a;
        // Octave and ray counts are checked as constants, not lowered as values.
        const size_t valueArgs = (fn == Builtin::Fbm || fn == Builtin::Turbulence)
                                     ? 1
                                     : (fn == Builtin::Occlusion ? 2 : e.args.size());
        for (size_t k = 0; k < valueArgs; ++k) a.push_back(expr(*e.args[k]));
        at(e.line, e.column);
        const ValueType rt = e.type;
        // A binding that repeats a bake() undoes it: its argument runs every frame there,
        // the override wrapping it as dynamic() would (expr()).
        if (fn == Builtin::Bake && repeatsThisBake(e)) return a[0];
        if (const std::optional<Op> op = componentwiseOp(fn)) return componentwise(*op, a, rt);
        switch (fn) {
            case Builtin::Dot:
                return scalarVal(dot(a[0], a[1]));
            case Builtin::Length:
                return scalarVal(b_.emit(Op::Sqrt, {dot(a[0], a[0])}));
            case Builtin::Distance: {
                Val d = componentwise(Op::Sub, {a[0], a[1]}, a[0].type);
                return scalarVal(b_.emit(Op::Sqrt, {dot(d, d)}));
            }
            case Builtin::Normalize: {
                // Division by a zero length gives 0 (safe division), OSL's normalize(0) = 0.
                const int len = b_.emit(Op::Sqrt, {dot(a[0], a[0])});
                return componentwise(Op::Div, {a[0], scalarVal(len)}, rt);
            }
            case Builtin::Cross: {
                Val out;
                out.type = rt;
                for (int k = 0; k < 3; ++k) {
                    const int i = (k + 1) % 3, j = (k + 2) % 3;
                    out.c[k] = b_.emit(Op::Sub, {b_.emit(Op::Mul, {a[0].c[i], a[1].c[j]}),
                                                 b_.emit(Op::Mul, {a[0].c[j], a[1].c[i]})});
                }
                return out;
            }
            case Builtin::Reflect: {
                // I - 2 dot(N, I) N
                const int twoDot = b_.emit(Op::Mul, {b_.constant(2.0f), dot(a[1], a[0])});
                Val scaled = componentwise(Op::Mul, {a[1], scalarVal(twoDot)}, a[1].type);
                return componentwise(Op::Sub, {a[0], scaled}, rt);
            }
            case Builtin::Faceforward: {
                // N facing against I, judged by the geometric normal (as OSL's 2-argument form).
                const int facing =
                    b_.emit(Op::Lt, {dot(a[1], global(GlobalId::Ng)), b_.constant(0.0f)});
                Val neg = componentwise(Op::Neg, {a[0]}, rt);
                return componentwise(Op::Select, {scalarVal(facing), a[0], neg}, rt);
            }
            case Builtin::Noise:
            case Builtin::Snoise:
            case Builtin::Cellnoise:
            case Builtin::Fbm:
            case Builtin::Turbulence:
                return noiseCall(fn, e, a[0]);
            case Builtin::Ambient:
                return ambientSum();
            case Builtin::Diffuse: {
                Val P = global(GlobalId::P);
                return lightSum(Op::Diffuse,
                                {P.c[0], P.c[1], P.c[2], a[0].c[0], a[0].c[1], a[0].c[2]});
            }
            case Builtin::Specular:
            case Builtin::Phong: {
                Val P = global(GlobalId::P);
                return lightSum(fn == Builtin::Specular ? Op::Specular : Op::Phong,
                                {P.c[0], P.c[1], P.c[2], a[0].c[0], a[0].c[1], a[0].c[2], a[1].c[0],
                                 a[1].c[1], a[1].c[2], a[2].c[0]});
            }
            case Builtin::Occlusion: {
                const int rays = constantInt(*e.args[2], "the occlusion ray count", 1, 1024);
                at(e.line, e.column);
                return scalarVal(b_.emit(
                    Op::Occlusion,
                    {a[0].c[0], a[0].c[1], a[0].c[2], a[1].c[0], a[1].c[1], a[1].c[2]}, 1, rays));
            }
            case Builtin::MakeColor:
            case Builtin::MakePoint:
            case Builtin::MakeVector:
            case Builtin::MakeNormal: {
                Val out;
                out.type = rt;
                for (int k = 0; k < 3; ++k)
                    out.c[k] =
                        a.size() == 3 ? a[k].c[0] : (isTriple(a[0].type) ? a[0].c[k] : a[0].c[0]);
                return out;
            }
            case Builtin::MakeFloat:
                return scalarVal(a[0].c[0]);
            case Builtin::MakeInt:
                return scalarVal(
                    a[0].type == ValueType::Int ? a[0].c[0] : b_.emit(Op::Trunc, {a[0].c[0]}),
                    ValueType::Int);
            default:  // None, and the componentwise builtins taken above
                break;
        }
        fail(e.line, e.column, "unknown function '" + e.name + "'");
    }

    void checkSize(const Stmt& s) {
        if (static_cast<int>(program_.insts.size()) > limits_.maxInstructions)
            fail(s.line, s.column,
                 "the shader exceeds " + std::to_string(limits_.maxInstructions) +
                     " instructions after unrolling its loops");
    }

    void assign(const Stmt& s) {
        const Expr& target = *s.target;
        const bool indexed = target.kind == Expr::Kind::Index;
        const std::string& name = indexed ? target.args[0]->name : target.name;
        Val* var = lookup(name);
        MPSHADE_CHECK(var != nullptr);
        Val value = expr(*s.value);
        at(s.line, s.column);
        int component = -1;
        Val current = *var;
        if (indexed) {
            component = constantInt(*target.args[1], "a component index", 0, 2);
            current = scalarVal(var->c[component]);
        }
        if (s.assignOp != TokenKind::Assign) {
            const bool intOp = current.type == ValueType::Int && value.type == ValueType::Int;
            const Op op = s.assignOp == TokenKind::PlusAssign    ? Op::Add
                          : s.assignOp == TokenKind::MinusAssign ? Op::Sub
                          : s.assignOp == TokenKind::StarAssign  ? Op::Mul
                                                                 : (intOp ? Op::IDiv : Op::Div);
            value = componentwise(op, {current, value}, current.type);
        }
        value = convert(value, current.type);
        var = lookup(name);  // re-find: lowering the value may not add scopes, but be safe
        if (indexed) {
            var->c[component] = value.c[0];
            describe(value, name + "[" + std::to_string(component) + "]");
        } else {
            *var = value;
            describe(value, name);
        }
    }

    void stmts(const std::vector<std::unique_ptr<Stmt>>& list) {
        scopes_.emplace_back();
        for (const auto& s : list) stmt(*s);
        scopes_.pop_back();
    }

    void stmt(const Stmt& s) {
        checkSize(s);
        switch (s.kind) {
            case Stmt::Kind::Block:
                stmts(s.body);
                break;
            case Stmt::Kind::Decl: {
                unbakeDecl_ = nullptr;
                for (const FactoringOverride& o : binding_.overrides)
                    if (o.kind == FactoringOverride::Kind::Repeat && o.line == 0 &&
                        o.name == s.name)
                        unbakeDecl_ = s.value.get();
                Val v = convert(expr(*s.value), s.declType);
                unbakeDecl_ = nullptr;
                for (size_t k = 0; k < binding_.overrides.size(); ++k)
                    if (binding_.overrides[k].line == 0 && binding_.overrides[k].name == s.name)
                        v = overridden(v, k, s.value->line, s.value->column);
                describe(v, s.name);
                scopes_.back()[s.name] = v;
                break;
            }
            case Stmt::Kind::Assign:
                assign(s);
                break;
            case Stmt::Kind::ExprStmt:
                expr(*s.value);
                break;
            case Stmt::Kind::If: {
                const int cond = expr(*s.value).c[0];
                float c;
                if (b_.constantValue(cond, c)) {
                    stmts(c != 0.0f ? s.body : s.elseBody);
                    break;
                }
                // Both branches run; every variable either changes becomes a select.
                const auto before = scopes_;
                stmts(s.body);
                const auto afterThen = scopes_;
                scopes_ = before;
                stmts(s.elseBody);
                at(s.line, s.column);
                for (size_t d = 0; d < scopes_.size(); ++d) {
                    for (auto& [name, elseVal] : scopes_[d]) {
                        const Val& thenVal = afterThen[d].at(name);
                        for (int k = 0; k < elseVal.n(); ++k)
                            if (thenVal.c[k] != elseVal.c[k])
                                elseVal.c[k] =
                                    b_.emit(Op::Select, {cond, thenVal.c[k], elseVal.c[k]});
                    }
                }
                break;
            }
            case Stmt::Kind::For: {
                scopes_.emplace_back();
                stmt(*s.init);
                for (int iteration = 0;; ++iteration) {
                    const int cond = expr(*s.value).c[0];
                    float c;
                    if (!b_.constantValue(cond, c))
                        fail(s.value->line, s.value->column,
                             "the loop condition must be constant after folding (loops are "
                             "unrolled); it depends on " +
                                 inputsReaching(cond));
                    if (c == 0.0f) break;
                    if (iteration >= limits_.maxLoopIterations)
                        fail(s.line, s.column,
                             "the loop runs more than " +
                                 std::to_string(limits_.maxLoopIterations) + " iterations");
                    stmts(s.body);
                    stmt(*s.step);
                }
                scopes_.pop_back();
                break;
            }
        }
    }

    const ShaderAst& ast_;
    std::vector<int> overrideMatches_;  // per binding override: expressions it wrapped
    const Expr* unbakeDecl_ = nullptr;  // the bake() call a 'repeat' of its variable undoes
    const ShaderBinding& binding_;
    const LoweringLimits& limits_;
    IrProgram& program_;
    IrBuilder b_;
    std::vector<std::map<std::string, Val>> scopes_;
};

}  // namespace

IrProgram lowerShader(const ShaderAst& ast, const ShaderBinding& binding,
                      const LoweringLimits& limits, FoldStats* stats) {
    IrProgram program;
    Lowerer lowerer(ast, binding, limits, program);
    lowerer.run();
    if (stats) *stats = lowerer.stats();
    return program;
}

}  // namespace mpshade
