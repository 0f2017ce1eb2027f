#include "shading/typecheck.h"

#include <map>

#include "geometry/error.h"

namespace mpshade {
namespace {

ValueType firstTriple(const std::vector<ValueType>& args) {
    for (ValueType t : args)
        if (isTriple(t)) return t;
    return ValueType::Float;
}

bool allScalarOrTriple(const std::vector<ValueType>& args) {
    for (ValueType t : args)
        if (!isScalar(t) && !isTriple(t)) return false;
    return true;
}

// Whether a value of type `from` may be stored where `to` is expected (spec: int -> float,
// float or int -> any 3-component type; nothing else implicitly).
bool assignable(ValueType from, ValueType to) {
    if (from == to) return true;
    if (to == ValueType::Float && from == ValueType::Int) return true;
    if (isTriple(to) && isScalar(from)) return true;
    return false;
}

// A builtin call's arguments checked against its signature; each check that fails says why.
class ArgumentCheck {
  public:
    ArgumentCheck(Builtin b, const std::vector<ValueType>& args, std::string& why)
        : b_(b), args_(args), why_(why) {}

    // Exactly n arguments, each a value.
    bool arity(size_t n) const {
        if (args_.size() != n) {
            why_ = std::string("'") + builtinName(b_) + "' takes " + std::to_string(n) +
                   (n == 1 ? " argument" : " arguments") + ", not " + std::to_string(args_.size());
            return false;
        }
        if (!allScalarOrTriple(args_)) {
            why_ = "arguments must be values";
            return false;
        }
        return true;
    }
    bool needTriple(size_t i) const {
        if (isTriple(args_[i])) return true;
        why_ = std::string("argument ") + std::to_string(i + 1) + " of '" + builtinName(b_) +
               "' must be a color, point, vector or normal, not " + typeName(args_[i]);
        return false;
    }
    bool needScalar(size_t i) const {
        if (isScalar(args_[i])) return true;
        why_ = std::string("argument ") + std::to_string(i + 1) + " of '" + builtinName(b_) +
               "' must be a float or int, not " + typeName(args_[i]);
        return false;
    }

  private:
    Builtin b_;
    const std::vector<ValueType>& args_;
    std::string& why_;
};

}  // namespace

ValueType builtinResultType(Builtin b, const std::vector<ValueType>& args, std::string& why) {
    const ArgumentCheck check(b, args, why);
    auto arity = [&](size_t n) { return check.arity(n); };
    auto needTriple = [&](size_t i) { return check.needTriple(i); };
    auto needScalar = [&](size_t i) { return check.needScalar(i); };
    switch (b) {
        case Builtin::Abs:
        case Builtin::Floor:
        case Builtin::Ceil:
        case Builtin::Fract:
        case Builtin::Sqrt:
        case Builtin::Exp:
        case Builtin::Log:
        case Builtin::Sin:
        case Builtin::Cos:
        case Builtin::Tan:
        case Builtin::Asin:
        case Builtin::Acos:
        case Builtin::Atan:
        case Builtin::Sign:
            if (!arity(1)) return ValueType::Void;
            return isTriple(args[0]) ? args[0] : ValueType::Float;
        case Builtin::Min:
        case Builtin::Max:
        case Builtin::Mod:
        case Builtin::Pow:
        case Builtin::Atan2:
        case Builtin::Step:
            if (!arity(2)) return ValueType::Void;
            return firstTriple(args);
        case Builtin::Clamp:
        case Builtin::Mix:
        case Builtin::Smoothstep:
            if (!arity(3)) return ValueType::Void;
            return firstTriple(args);
        case Builtin::Dot:
        case Builtin::Distance:
            if (!arity(2) || !needTriple(0) || !needTriple(1)) return ValueType::Void;
            return ValueType::Float;
        case Builtin::Cross:
        case Builtin::Reflect:
        case Builtin::Faceforward:
            if (!arity(2) || !needTriple(0) || !needTriple(1)) return ValueType::Void;
            return args[0];
        case Builtin::Length:
            if (!arity(1) || !needTriple(0)) return ValueType::Void;
            return ValueType::Float;
        case Builtin::Normalize:
            if (!arity(1) || !needTriple(0)) return ValueType::Void;
            return args[0];
        case Builtin::Noise:
        case Builtin::Snoise:
        case Builtin::Cellnoise:
            if (!arity(1)) return ValueType::Void;
            return ValueType::Float;
        case Builtin::Fbm:
        case Builtin::Turbulence:
            if (!arity(2) || !needScalar(1)) return ValueType::Void;
            return ValueType::Float;
        case Builtin::Ambient:
            if (!args.empty()) {
                why = "'ambient' takes no arguments";
                return ValueType::Void;
            }
            return ValueType::Color;
        case Builtin::Diffuse:
            if (!arity(1) || !needTriple(0)) return ValueType::Void;
            return ValueType::Color;
        case Builtin::Specular:
        case Builtin::Phong:
            if (!arity(3) || !needTriple(0) || !needTriple(1) || !needScalar(2))
                return ValueType::Void;
            return ValueType::Color;
        case Builtin::Occlusion:
            if (!arity(3) || !needTriple(0) || !needTriple(1) || !needScalar(2))
                return ValueType::Void;
            return ValueType::Float;
        case Builtin::Bake:
        case Builtin::Dynamic:
            if (!arity(1)) return ValueType::Void;
            return args[0];
        case Builtin::MakeColor:
        case Builtin::MakePoint:
        case Builtin::MakeVector:
        case Builtin::MakeNormal: {
            static const ValueType kResult[] = {ValueType::Color, ValueType::Point,
                                                ValueType::Vector, ValueType::Normal};
            const ValueType result =
                kResult[static_cast<int>(b) - static_cast<int>(Builtin::MakeColor)];
            if (args.size() == 1 && (isScalar(args[0]) || isTriple(args[0]))) return result;
            if (args.size() == 3 && isScalar(args[0]) && isScalar(args[1]) && isScalar(args[2]))
                return result;
            why = std::string("'") + builtinName(b) +
                  "' takes three floats, or one float or 3-component value";
            return ValueType::Void;
        }
        case Builtin::MakeFloat:
        case Builtin::MakeInt:
            if (!arity(1) || !needScalar(0)) return ValueType::Void;
            return b == Builtin::MakeFloat ? ValueType::Float : ValueType::Int;
        case Builtin::None:
            break;
    }
    why = "unknown function";
    return ValueType::Void;
}

namespace {

class TypeChecker {
  public:
    explicit TypeChecker(ShaderAst& ast) : ast_(ast) {}

    void run() {
        for (auto& p : ast_.params) {
            GlobalId g;
            ValueType gt;
            if (findGlobal(p.name, g, gt) || p.name == "Ci" || p.name == "Oi")
                fail(p.line, p.column, "parameter '" + p.name + "' has the name of a global");
            if (findBuiltin(p.name) != Builtin::None)
                fail(p.line, p.column,
                     "parameter '" + p.name + "' has the name of a built-in function");
            // Defaults see no globals and no other parameters: they are constants.
            scopes_.assign(1, {});
            ValueType t = expr(*p.defaultValue);
            if (!assignable(t, p.type))
                fail(p.defaultValue->line, p.defaultValue->column,
                     std::string("default of '") + p.name + "' is " + typeName(t) + ", expected " +
                         typeName(p.type));
            for (const auto& q : ast_.params) {
                if (&q == &p) break;
                if (q.name == p.name)
                    fail(p.line, p.column, "parameter '" + p.name + "' is declared twice");
            }
        }
        scopes_.assign(1, {});
        for (auto& p : ast_.params) scopes_[0][p.name] = p.type;
        scopes_[0]["Ci"] = ValueType::Color;
        scopes_[0]["Oi"] = ValueType::Color;
        stmt(*ast_.body);
        if (!ciAssigned_)
            fail(ast_.line, ast_.column, "shader '" + ast_.name + "' never assigns Ci");
    }

  private:
    [[noreturn]] void fail(int line, int col, const std::string& msg) const {
        throw InputError({ast_.file, line, col, {}}, msg);
    }

    bool lookup(const std::string& name, ValueType& t) const {
        for (auto it = scopes_.rbegin(); it != scopes_.rend(); ++it) {
            auto f = it->find(name);
            if (f != it->end()) {
                t = f->second;
                return true;
            }
        }
        GlobalId g;
        return findGlobal(name, g, t);
    }

    void declare(const Stmt& s) {
        GlobalId g;
        ValueType gt;
        if (findGlobal(s.name, g, gt) || s.name == "Ci" || s.name == "Oi")
            fail(s.line, s.column, "'" + s.name + "' is a global and cannot be redeclared");
        if (findBuiltin(s.name) != Builtin::None)
            fail(s.line, s.column,
                 "'" + s.name + "' is a built-in function and cannot name a variable");
        if (scopes_.back().count(s.name))
            fail(s.line, s.column, "'" + s.name + "' is already declared in this scope");
        scopes_.back()[s.name] = s.declType;
    }

    void stmt(Stmt& s) {
        switch (s.kind) {
            case Stmt::Kind::Block:
                scopes_.emplace_back();
                for (auto& c : s.body) stmt(*c);
                scopes_.pop_back();
                break;
            case Stmt::Kind::Decl: {
                ValueType t = expr(*s.value);
                if (!assignable(t, s.declType))
                    fail(s.value->line, s.value->column,
                         std::string("cannot initialize ") + typeName(s.declType) + " '" + s.name +
                             "' with a " + typeName(t) + hint(t, s.declType));
                declare(s);
                break;
            }
            case Stmt::Kind::Assign: {
                const Expr& target = *s.target;
                const Expr& var = target.kind == Expr::Kind::Index ? *target.args[0] : target;
                ValueType vt;
                if (!lookup(var.name, vt))
                    fail(var.line, var.column, "unknown variable '" + var.name + "'");
                GlobalId g;
                ValueType gt;
                if (findGlobal(var.name, g, gt) && !isShadowed(var.name))
                    fail(var.line, var.column, "'" + var.name + "' is a read-only global");
                if (var.name == "Ci") ciAssigned_ = true;
                ValueType targetType = vt;
                if (target.kind == Expr::Kind::Index) {
                    targetType = expr(*s.target);
                }
                ValueType value = expr(*s.value);
                if (s.assignOp != TokenKind::Assign) {
                    std::string why;
                    value = arithmeticType(targetType, value, why);
                    if (value == ValueType::Void) fail(s.line, s.column, why);
                }
                if (!assignable(value, targetType))
                    fail(s.value->line, s.value->column,
                         std::string("cannot assign a ") + typeName(value) + " to " +
                             typeName(targetType) + " '" + var.name + "'" +
                             hint(value, targetType));
                break;
            }
            case Stmt::Kind::ExprStmt:
                // The language has no side effects: `bake(c);` or `noise(P);` alone would
                // silently do nothing.
                expr(*s.value);
                fail(s.line, s.column,
                     "this statement does nothing: an expression alone has no effect (the "
                     "language has no side effects); assign its value, as in 'float y = ...;'");
            case Stmt::Kind::If:
                condition(*s.value, "if");
                scopes_.emplace_back();
                for (auto& c : s.body) stmt(*c);
                scopes_.pop_back();
                scopes_.emplace_back();
                for (auto& c : s.elseBody) stmt(*c);
                scopes_.pop_back();
                break;
            case Stmt::Kind::For:
                scopes_.emplace_back();
                stmt(*s.init);
                condition(*s.value, "for");
                stmt(*s.step);
                scopes_.emplace_back();
                for (auto& c : s.body) stmt(*c);
                scopes_.pop_back();
                scopes_.pop_back();
                break;
        }
    }

    bool isShadowed(const std::string& name) const {
        for (const auto& scope : scopes_)
            if (scope.count(name)) return true;
        return false;
    }

    static std::string hint(ValueType from, ValueType to) {
        if (to == ValueType::Int && from == ValueType::Float) return " (use int(x) to truncate)";
        if (isTriple(from) && isTriple(to))
            return std::string(" (convert explicitly with ") + typeName(to) + "(x))";
        return "";
    }

    void condition(Expr& e, const char* what) {
        ValueType t = expr(e);
        if (!isScalar(t))
            fail(e.line, e.column,
                 std::string("the condition of '") + what + "' must be a float or int, not " +
                     typeName(t));
    }

    static ValueType arithmeticType(ValueType a, ValueType b, std::string& why) {
        if (isScalar(a) && isScalar(b))
            return (a == ValueType::Int && b == ValueType::Int) ? ValueType::Int : ValueType::Float;
        if (isTriple(a) && (isTriple(b) || isScalar(b))) return a;
        if (isScalar(a) && isTriple(b)) return b;
        why = std::string("cannot combine ") + typeName(a) + " and " + typeName(b);
        return ValueType::Void;
    }

    ValueType expr(Expr& e) {
        e.type = exprType(e);
        return e.type;
    }

    ValueType exprType(Expr& e) {
        switch (e.kind) {
            case Expr::Kind::Number:
                return e.isInt ? ValueType::Int : ValueType::Float;
            case Expr::Kind::Name: {
                ValueType t;
                if (!lookup(e.name, t)) {
                    if (findBuiltin(e.name) != Builtin::None)
                        fail(e.line, e.column,
                             "'" + e.name + "' is a function; call it with '(...)'");
                    fail(e.line, e.column, "unknown variable '" + e.name + "'");
                }
                return t;
            }
            case Expr::Kind::Unary: {
                ValueType t = expr(*e.args[0]);
                if (e.op == TokenKind::Bang) {
                    if (!isScalar(t))
                        fail(e.line, e.column,
                             std::string("'!' needs a float or int, not ") + typeName(t));
                    return ValueType::Int;
                }
                if (!isScalar(t) && !isTriple(t)) fail(e.line, e.column, "'-' needs a value");
                return t;
            }
            case Expr::Kind::Binary: {
                ValueType a = expr(*e.args[0]), b = expr(*e.args[1]);
                switch (e.op) {
                    case TokenKind::Plus:
                    case TokenKind::Minus:
                    case TokenKind::Star:
                    case TokenKind::Slash: {
                        std::string why;
                        ValueType t = arithmeticType(a, b, why);
                        if (t == ValueType::Void) fail(e.line, e.column, why);
                        return t;
                    }
                    case TokenKind::Less:
                    case TokenKind::LessEq:
                    case TokenKind::Greater:
                    case TokenKind::GreaterEq:
                        if (!isScalar(a) || !isScalar(b))
                            fail(e.line, e.column,
                                 std::string("cannot order ") + typeName(a) + " and " +
                                     typeName(b) + "; compare components");
                        return ValueType::Int;
                    case TokenKind::EqEq:
                    case TokenKind::NotEq:
                        if (!((isScalar(a) && isScalar(b)) || (isTriple(a) && isTriple(b))))
                            fail(e.line, e.column,
                                 std::string("cannot compare ") + typeName(a) + " and " +
                                     typeName(b));
                        return ValueType::Int;
                    case TokenKind::AndAnd:
                    case TokenKind::OrOr:
                        if (!isScalar(a) || !isScalar(b))
                            fail(e.line, e.column, "'&&' and '||' need float or int operands");
                        return ValueType::Int;
                    default:
                        fail(e.line, e.column, "unexpected operator");
                }
            }
            case Expr::Kind::Index: {
                ValueType base = expr(*e.args[0]);
                ValueType idx = expr(*e.args[1]);
                if (!isTriple(base))
                    fail(e.line, e.column,
                         std::string("only 3-component values can be indexed, not ") +
                             typeName(base));
                if (idx != ValueType::Int)
                    fail(e.args[1]->line, e.args[1]->column, "a component index must be an int");
                return ValueType::Float;
            }
            case Expr::Kind::Call: {
                Builtin b = findBuiltin(e.name);
                if (b == Builtin::None) {
                    ValueType t;
                    if (lookup(e.name, t))
                        fail(e.line, e.column, "'" + e.name + "' is a variable, not a function");
                    if (e.name == "texture" || e.name == "environment")
                        fail(e.line, e.column,
                             "unknown function '" + e.name +
                                 "': shaders are procedural and read no image files (use "
                                 "noise, fbm, turbulence or cellnoise)");
                    fail(e.line, e.column, "unknown function '" + e.name + "'");
                }
                // bake() computes its whole argument in the static phase: a dynamic() in it
                // would be silently overruled. (A bake() inside dynamic() is meaningful: that
                // part stays stored, the rest is repeated.)
                if (b == Builtin::Bake && !e.args.empty())
                    if (const Expr* c = findCall(*e.args[0], "dynamic"))
                        fail(c->line, c->column,
                             "dynamic() inside bake() (line " + std::to_string(e.line) + ":" +
                                 std::to_string(e.column) +
                                 "): bake() computes its whole argument in the static phase, so "
                                 "this dynamic() would have no effect; remove one of them");
                std::vector<ValueType> args;
                for (auto& a : e.args) args.push_back(expr(*a));
                std::string why;
                ValueType t = builtinResultType(b, args, why);
                if (t == ValueType::Void) fail(e.line, e.column, why);
                return t;
            }
        }
        return ValueType::Void;
    }

    // The first call of `name` in e's tree, or null.
    static const Expr* findCall(const Expr& e, const char* name) {
        if (e.kind == Expr::Kind::Call && e.name == name) return &e;
        for (const auto& a : e.args)
            if (const Expr* c = findCall(*a, name)) return c;
        return nullptr;
    }

    ShaderAst& ast_;
    std::vector<std::map<std::string, ValueType>> scopes_;
    bool ciAssigned_ = false;
};

}  // namespace

void typecheckShader(ShaderAst& ast) {
    TypeChecker(ast).run();
}

}  // namespace mpshade
