// Each builtin against a direct C++ formula, both when it runs in the interpreter and when
// the constant folder evaluates it: the two must agree bit for bit.
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <random>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "shading/noise.h"
#include "shading/shader_harness.h"

namespace mpshade {
namespace {

using test::ShadingPoint;

struct Case {
    const char* expr;  // in terms of u, v, s
    std::function<float(float, float, float)> expected;
};

float safeDiv(float a, float b) {
    return b == 0.0f ? 0.0f : a / b;
}

const Case kCases[] = {
    {"abs(u)", [](float u, float, float) { return std::fabs(u); }},
    {"floor(u)", [](float u, float, float) { return std::floor(u); }},
    {"ceil(u)", [](float u, float, float) { return std::ceil(u); }},
    {"fract(u)", [](float u, float, float) { return u - std::floor(u); }},
    {"sqrt(u)", [](float u, float, float) { return u > 0 ? std::sqrt(u) : 0.0f; }},
    {"exp(u)", [](float u, float, float) { return std::exp(u); }},
    {"log(u)", [](float u, float, float) { return std::log(std::fmax(u, 1.17549435e-38f)); }},
    {"sin(u)", [](float u, float, float) { return std::sin(u); }},
    {"cos(u)", [](float u, float, float) { return std::cos(u); }},
    {"tan(u)", [](float u, float, float) { return std::tan(u); }},
    {"asin(u)",
     [](float u, float, float) { return std::asin(std::fmin(std::fmax(u, -1.0f), 1.0f)); }},
    {"acos(u)",
     [](float u, float, float) { return std::acos(std::fmin(std::fmax(u, -1.0f), 1.0f)); }},
    {"atan(u)", [](float u, float, float) { return std::atan(u); }},
    {"sign(u)", [](float u, float, float) { return u > 0 ? 1.0f : (u < 0 ? -1.0f : 0.0f); }},
    {"min(u, v)", [](float u, float v, float) { return std::fmin(u, v); }},
    {"max(u, v)", [](float u, float v, float) { return std::fmax(u, v); }},
    {"mod(u, v)",
     [](float u, float v, float) { return v == 0 ? 0.0f : u - v * std::floor(u / v); }},
    {"pow(u, v)",
     [](float u, float v, float) {
         if (u == 0) return 0.0f;
         if (u < 0 && v != std::floor(v)) return 0.0f;
         return std::pow(u, v);
     }},
    {"atan2(u, v)", [](float u, float v, float) { return std::atan2(u, v); }},
    {"step(u, v)", [](float u, float v, float) { return v < u ? 0.0f : 1.0f; }},
    {"clamp(u, v, s)", [](float u, float v, float s) { return std::fmin(std::fmax(u, v), s); }},
    {"mix(u, v, s)", [](float u, float v, float s) { return u * (1 - s) + v * s; }},
    {"smoothstep(v, v + 1.0, u)",
     [](float u, float v, float) {
         float t = std::fmin(std::fmax((u - v) / ((v + 1.0f) - v), 0.0f), 1.0f);
         return t * t * (3 - 2 * t);
     }},
    // Equal edges: a step at the edge, 1 on it.
    {"smoothstep(v, v, u)", [](float u, float v, float) { return u < v ? 0.0f : 1.0f; }},
    {"smoothstep(u, u, u)", [](float, float, float) { return 1.0f; }},
    {"u / v", [](float u, float v, float) { return safeDiv(u, v); }},
    {"u * v - s", [](float u, float v, float s) { return u * v - s; }},
    {"-u + v", [](float u, float v, float) { return -u + v; }},
    {"float(u < v)", [](float u, float v, float) { return u < v ? 1.0f : 0.0f; }},
    {"float(u >= v && v != s)",
     [](float u, float v, float s) { return (u >= v && v != s) ? 1.0f : 0.0f; }},
    {"float(u > v || !(s <= u))",
     [](float u, float v, float s) { return (u > v || !(s <= u)) ? 1.0f : 0.0f; }},
    {"float(int(u))", [](float u, float, float) { return std::trunc(u); }},
    {"float(int(u) / int(v))",
     [](float u, float v, float) { return std::trunc(safeDiv(std::trunc(u), std::trunc(v))); }},
    {"dot(vector(u, v, s), vector(v, s, u))",
     [](float u, float v, float s) { return u * v + v * s + s * u; }},
    {"cross(vector(u, v, s), vector(v, s, u))[0]",
     [](float u, float v, float s) { return v * u - s * s; }},
    {"length(vector(u, v, s))",
     [](float u, float v, float s) { return std::sqrt(u * u + v * v + s * s); }},
    {"distance(point(u, v, s), point(0.5))",
     [](float u, float v, float s) {
         return std::sqrt((u - .5f) * (u - .5f) + (v - .5f) * (v - .5f) + (s - .5f) * (s - .5f));
     }},
    {"normalize(vector(u, v, s))[1]",
     [](float u, float v, float s) {
         float l = std::sqrt(u * u + v * v + s * s);
         return l == 0 ? 0.0f : v / l;
     }},
    {"reflect(vector(u, v, s), normal(0, 1, 0))[1]",
     [](float, float v, float) { return v - 2 * v; }},
    {"noise(point(u, v, s))", [](float u, float v, float s) { return noise3(u, v, s); }},
    {"snoise(point(u, v, s))", [](float u, float v, float s) { return snoise3(u, v, s); }},
    {"snoise(u)", [](float u, float, float) { return snoise3(u, 0, 0); }},
    {"cellnoise(point(u, v, s))", [](float u, float v, float s) { return cellnoise3(u, v, s); }},
    {"fbm(point(u, v, s), 5)",
     [](float u, float v, float s) {
         float sum = 0, amp = 1, f = 1;
         for (int i = 0; i < 5; ++i, amp *= 0.5f, f *= 2.0f)
             sum += amp * snoise3(u * f, v * f, s * f);
         return sum;
     }},
    {"turbulence(point(u, v, s), 3)",
     [](float u, float v, float s) {
         float sum = 0, amp = 1, f = 1;
         for (int i = 0; i < 3; ++i, amp *= 0.5f, f *= 2.0f)
             sum += amp * std::fabs(snoise3(u * f, v * f, s * f));
         return sum;
     }},
    {"bake(u) + dynamic(v)", [](float u, float v, float) { return u + v; }},
};

std::string literal(float x) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.9g", static_cast<double>(x));
    std::string s = buffer;
    if (s.find_first_of(".e") == std::string::npos) s += ".0";
    return "(" + s + ")";
}

std::string substitute(std::string expr, float u, float v, float s) {
    std::string out;
    for (size_t i = 0; i < expr.size(); ++i) {
        const char c = expr[i];
        const bool word =
            (i > 0 &&
             (std::isalnum(static_cast<unsigned char>(expr[i - 1])) || expr[i - 1] == '_')) ||
            (i + 1 < expr.size() &&
             (std::isalnum(static_cast<unsigned char>(expr[i + 1])) || expr[i + 1] == '_'));
        if (!word && c == 'u')
            out += literal(u);
        else if (!word && c == 'v')
            out += literal(v);
        else if (!word && c == 's')
            out += literal(s);
        else
            out += c;
    }
    return out;
}

TEST(Builtins, InterpreterAndFolderMatchTheFormula) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> uni(-2.5f, 2.5f);
    std::vector<ShadingPoint> points;
    for (int i = 0; i < 300; ++i) {
        ShadingPoint p;
        p.u = uni(rng), p.v = uni(rng), p.s = uni(rng);
        if (i % 10 == 0) p.v = 0.0f;  // division and mod by zero
        if (i % 17 == 0) p.u = std::floor(p.u);
        points.push_back(p);
    }
    for (const Case& c : kCases) {
        const std::string shader = std::string("surface t() { Ci = color(") + c.expr + "); }";
        const auto result = test::runShader(shader, points);
        for (size_t i = 0; i < points.size(); ++i) {
            const ShadingPoint& p = points[i];
            const float expected = c.expected(p.u, p.v, p.s);
            const float tolerance = 2e-6f * std::fmax(1.0f, std::fabs(expected));
            ASSERT_NEAR(result.Ci[i].x, expected, tolerance)
                << c.expr << " at u=" << p.u << " v=" << p.v << " s=" << p.s;
            if (i % 30 == 0) {
                // The same expression on literals is folded at compile time.
                const std::string folded = std::string("surface t() { Ci = color(") +
                                           substitute(c.expr, p.u, p.v, p.s) + "); }";
                const auto f = test::runShader(folded, {p});
                ASSERT_EQ(f.counters.instructions, 0u) << folded << " should fold to a constant";
                ASSERT_EQ(f.Ci[0].x, result.Ci[i].x) << folded;
            }
        }
    }
}

// `expr` with variable `name` (u, v or s) replaced by the literal x (infinities written as
// overflowing products, which fold to them).
std::string substituteOne(const std::string& expr, char name, float x) {
    const std::string lit =
        std::isinf(x) ? (x > 0 ? "(1e38 * 10.0)" : "(-1e38 * 10.0)") : literal(x);
    std::string out;
    for (size_t i = 0; i < expr.size(); ++i) {
        const auto wordChar = [&](size_t k) {
            return std::isalnum(static_cast<unsigned char>(expr[k])) || expr[k] == '_';
        };
        const bool word = (i > 0 && wordChar(i - 1)) || (i + 1 < expr.size() && wordChar(i + 1));
        out += !word && expr[i] == name ? lit : std::string(1, expr[i]);
    }
    return out;
}

bool sameBits(float a, float b) {
    return (std::isnan(a) && std::isnan(b)) || std::memcmp(&a, &b, sizeof a) == 0;
}

TEST(Builtins, FoldingEachOperandInTurnMatchesTheInterpreter) {
    // The folder's partial rules (x * 1, x + 0, min of a constant, ...) act when only some
    // operands are constant. Each operand in turn becomes a literal, the others stay inputs;
    // over special values (signed zeros, infinities, NaN inputs, huge) the result must be
    // the interpreter's on all-variable inputs, bit for bit. A rule such as x * 0 -> 0
    // (wrong for infinities and NaN) or x + 0 -> x (wrong for -0) fails here.
    const float inf = std::numeric_limits<float>::infinity();
    const float values[] = {0.0f, -0.0f, 1.0f, -1.0f, 0.5f, -2.5f, 3.0f, 1e30f, inf, -inf, NAN};
    struct Op {
        const char* expr;
        int arity;  // uses u, v (and s)
    };
    const Op kOps[] = {
        {"abs(u)", 1},
        {"floor(u)", 1},
        {"ceil(u)", 1},
        {"fract(u)", 1},
        {"sqrt(u)", 1},
        {"exp(u)", 1},
        {"log(u)", 1},
        {"sin(u)", 1},
        {"cos(u)", 1},
        {"tan(u)", 1},
        {"asin(u)", 1},
        {"acos(u)", 1},
        {"atan(u)", 1},
        {"sign(u)", 1},
        {"-u", 1},
        {"float(int(u))", 1},
        {"float(!(u > 0))", 1},
        {"snoise(u)", 1},
        {"cellnoise(u)", 1},
        {"u + v", 2},
        {"u - v", 2},
        {"u * v", 2},
        {"u / v", 2},
        {"min(u, v)", 2},
        {"max(u, v)", 2},
        {"mod(u, v)", 2},
        {"pow(u, v)", 2},
        {"atan2(u, v)", 2},
        {"step(u, v)", 2},
        {"float(u < v)", 2},
        {"float(u == v)", 2},
        {"float(u != v)", 2},
        {"float(u > 0 && v > 0)", 2},
        {"float(u > 0 || v > 0)", 2},
        {"-u * v", 2},
        {"mix(u, v, s)", 3},
        {"clamp(u, v, s)", 3},
        {"smoothstep(u, v, s)", 3},
        {"u * v + s", 3},
    };
    const char names[] = {'u', 'v', 's'};
    for (const Op& op : kOps) {
        std::vector<ShadingPoint> points;
        const size_t n = std::size(values);
        const size_t combos = op.arity == 1 ? n : op.arity == 2 ? n * n : n * n * n;
        for (size_t c = 0; c < combos; ++c) {
            ShadingPoint p;
            p.u = values[c % n];
            p.v = op.arity >= 2 ? values[(c / n) % n] : 0.0f;
            p.s = op.arity == 3 ? values[c / (n * n)] : 0.0f;
            points.push_back(p);
        }
        const std::string body = std::string("surface t() { Ci = color(") + op.expr + "); }";
        const auto all = test::runShader(body, points);
        for (int k = 0; k < op.arity; ++k)
            for (float x : values) {
                if (std::isnan(x)) continue;  // no NaN literal in the language
                std::vector<ShadingPoint> subset;
                std::vector<size_t> index;
                for (size_t i = 0; i < points.size(); ++i) {
                    const float here = k == 0 ? points[i].u : k == 1 ? points[i].v : points[i].s;
                    if (sameBits(here, x)) subset.push_back(points[i]), index.push_back(i);
                }
                const std::string folded = substituteOne(body, names[k], x);
                const auto some = test::runShader(folded, subset);
                for (size_t i = 0; i < subset.size(); ++i)
                    ASSERT_TRUE(sameBits(some.Ci[i].x, all.Ci[index[i]].x))
                        << folded << " at u=" << subset[i].u << " v=" << subset[i].v
                        << " s=" << subset[i].s << ": " << some.Ci[i].x << " folded, "
                        << all.Ci[index[i]].x << " interpreted";
            }
    }
}

TEST(Builtins, FaceforwardUsesTheGeometricNormal) {
    ShadingPoint p;
    p.N = glm::vec3(0, 1, 0);
    p.Ng = glm::vec3(0, 1, 0);
    p.I = glm::vec3(0, -1, 0);  // looking down at the front
    ShadingPoint back = p;
    back.I = glm::vec3(0, 1, 0);  // looking up at the back
    const auto r = test::runShader("surface t() { Ci = color(faceforward(N, I)); }", {p, back});
    EXPECT_EQ(r.Ci[0].y, 1.0f);
    EXPECT_EQ(r.Ci[1].y, -1.0f);
}

TEST(Builtins, TripleArithmeticBroadcastsScalars) {
    ShadingPoint p;
    p.P = glm::vec3(1, 2, 3);
    const auto r = test::runShader(
        "surface t() { color c = color(P[0], P[1], P[2]); Ci = c * 2 + 1; Ci[1] = -1; Ci /= 2; }",
        {p});
    EXPECT_EQ(r.Ci[0], glm::vec3(1.5f, -0.5f, 3.5f));
    EXPECT_EQ(r.Oi[0], glm::vec3(1.0f));
}

TEST(Builtins, IfBecomesSelectAndLoopsUnroll) {
    std::vector<ShadingPoint> pts(4);
    for (int i = 0; i < 4; ++i) pts[i].u = static_cast<float>(i);
    const char* src = R"(
        surface t() {
            float acc = 0;
            for (int i = 0; i < 5; i += 1) {
                if (u > 1.5) { acc += i; } else { acc -= 1; }
            }
            float odd = 0;
            for (int k = 1; k <= 9; k += 2) { odd += k; }
            Ci = color(acc, odd, 0);
        })";
    const auto r = test::runShader(src, pts);
    EXPECT_EQ(r.Ci[0].x, -5.0f);
    EXPECT_EQ(r.Ci[1].x, -5.0f);
    EXPECT_EQ(r.Ci[2].x, 10.0f);
    EXPECT_EQ(r.Ci[3].x, 10.0f);
    EXPECT_EQ(r.Ci[0].y, 25.0f);
}

TEST(Builtins, NaNPolicyKeepsFiniteInputsFinite) {
    std::vector<ShadingPoint> pts(3);
    pts[0].u = 0.0f;
    pts[1].u = -1.0f;
    pts[2].u = -8.0f;
    const auto r = test::runShader(
        "surface t() { Ci = color(1 / u + sqrt(u) + log(u) * 0 + pow(u, 0.5) + asin(u * 9), mod(1, "
        "u * 0), normalize(vector(0))[0]); }",
        pts);
    for (const auto& c : r.Ci) {
        EXPECT_TRUE(std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z));
    }
    EXPECT_EQ(r.Ci[0].x, 0.0f + 0.0f + 0.0f + 0.0f + std::asin(0.0f));
}

TEST(Builtins, ParametersBindAsConstantsOrAnimatedInputs) {
    const char* src = "surface t(float k = 2, color c = color(1, 2, 3)) { Ci = c * k; }";
    ShadingPoint p;
    // Defaults fold completely.
    auto r = test::runShader(src, {p});
    EXPECT_EQ(r.Ci[0], glm::vec3(2, 4, 6));
    EXPECT_EQ(r.counters.instructions, 0u);
    // A constant binding folds too.
    ShaderBinding constant;
    constant.params["k"].kind = ParamBinding::Kind::Constant;
    constant.params["k"].value[0] = 3.0f;
    r = test::runShader(src, {p}, constant);
    EXPECT_EQ(r.Ci[0], glm::vec3(3, 6, 9));
    EXPECT_EQ(r.counters.instructions, 0u);
    // An animated one is read from the per-frame block.
    ShaderBinding animated;
    animated.params["k"].kind = ParamBinding::Kind::Animated;
    auto ast = compileShaderText("t.sl", src);
    auto kernel = buildKernel(*ast, animated);
    ASSERT_EQ(kernel->program().paramFloats, 1);
    const float block[] = {5.0f};
    ShadingUniforms uniforms;
    uniforms.params = block;
    r = test::runKernel(*kernel, {p}, uniforms);
    EXPECT_EQ(r.Ci[0], glm::vec3(5, 10, 15));
}

}  // namespace
}  // namespace mpshade
