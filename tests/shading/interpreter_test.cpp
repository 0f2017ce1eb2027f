// The batched interpreter against a plain one-value-at-a-time evaluation of the same IR,
// on random programs with many temporaries, branches and loops (this is what catches a
// register reused too early), over batches that do not fill the last chunk.
#include <random>
#include <sstream>

#include <gtest/gtest.h>

#include "shading/lower.h"
#include "shading/scalar_ops.h"
#include "shading/shader_harness.h"

namespace mpshade {
namespace {

using test::ShadingPoint;

// Evaluates the IR for one point with one slot per value: no registers, no batching.
glm::vec3 evaluateIr(const IrProgram& ir, const ShadingPoint& p) {
    std::vector<float> value(static_cast<size_t>(ir.valueCount), 0.0f);
    for (const Inst& inst : ir.insts) {
        const int32_t* a = ir.argsOf(inst);
        auto arg = [&](int k) { return value[static_cast<size_t>(a[k])]; };
        float& out = value[static_cast<size_t>(inst.result)];
        switch (inst.op) {
            case Op::Const:
                out = inst.constant;
                break;
            case Op::Global: {
                const auto id = static_cast<GlobalId>(inst.imm);
                const glm::vec3* triple = id == GlobalId::P   ? &p.P
                                          : id == GlobalId::N ? &p.N
                                          : id == GlobalId::I ? &p.I
                                                              : nullptr;
                if (triple) {
                    for (int k = 0; k < 3; ++k)
                        value[static_cast<size_t>(inst.result + k)] = (*triple)[k];
                } else {
                    out = id == GlobalId::u   ? p.u
                          : id == GlobalId::v ? p.v
                          : id == GlobalId::s ? p.s
                                              : p.t;
                }
                break;
            }
            default:
                if (inst.nargs == 1)
                    out = scalar::unary(inst.op, arg(0));
                else if (inst.nargs == 2)
                    out = scalar::binary(inst.op, arg(0), arg(1));
                else if (inst.op >= Op::Noise && inst.op <= Op::Turbulence)
                    out = scalar::pattern(inst.op, inst.imm, arg(0), arg(1), arg(2));
                else
                    out = scalar::ternary(inst.op, arg(0), arg(1), arg(2));
        }
    }
    return {value[static_cast<size_t>(ir.ci[0])], value[static_cast<size_t>(ir.ci[1])],
            value[static_cast<size_t>(ir.ci[2])]};
}

std::string randomProgram(std::mt19937& rng, int statements) {
    std::vector<std::string> vars = {"u", "v", "s", "P[0]", "P[1]", "N[2]"};
    std::ostringstream src;
    src << "surface r() {\n";
    auto pick = [&]() { return vars[rng() % vars.size()]; };
    static const char* kBinary[] = {"+", "-", "*", "/"};
    static const char* kFns[] = {"sin", "abs", "fract", "sqrt", "floor"};
    static const char* kFns2[] = {"min", "max", "mod", "step", "atan2"};
    for (int i = 0; i < statements; ++i) {
        const std::string name = "t" + std::to_string(i);
        std::string e;
        switch (rng() % 6) {
            case 0:
            case 1:
                e = pick() + " " + kBinary[rng() % 4] + " " + pick();
                break;
            case 2:
                e = std::string(kFns[rng() % 5]) + "(" + pick() + ")";
                break;
            case 3:
                e = std::string(kFns2[rng() % 5]) + "(" + pick() + ", " + pick() + ")";
                break;
            case 4:
                e = "mix(" + pick() + ", " + pick() + ", " + pick() + ")";
                break;
            case 5:
                e = "snoise(point(" + pick() + ", " + pick() + ", 0.5))";
                break;
        }
        src << "    float " << name << " = " << e << ";\n";
        if (rng() % 5 == 0) {
            src << "    if (" << pick() << " > " << pick() << ") { " << name << " = " << pick()
                << " * 2; } else { " << name << " -= 1; }\n";
        }
        if (rng() % 9 == 0) {
            src << "    for (int k = 0; k < 3; k += 1) { " << name << " += " << pick()
                << " * k; }\n";
        }
        vars.push_back(name);
    }
    src << "    Ci = color(" << vars.back() << ", " << pick() << ", " << pick() << ");\n}\n";
    return src.str();
}

TEST(Interpreter, MatchesOneValueAtATimeEvaluationOnRandomPrograms) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> uni(-3.0f, 3.0f);
    std::vector<ShadingPoint> points(ShaderKernel::kLanes * 2 + 37);
    for (auto& p : points) {
        p.u = uni(rng), p.v = uni(rng), p.s = uni(rng);
        p.P = glm::vec3(uni(rng), uni(rng), uni(rng));
        p.N = glm::vec3(uni(rng), uni(rng), uni(rng));
    }
    for (int program = 0; program < 60; ++program) {
        const std::string src = randomProgram(rng, 10 + program * 2);
        auto ast = compileShaderText("random.sl", src);
        const IrProgram ir = lowerShader(*ast, {});
        const ShaderKernel kernel(ir);
        EXPECT_LT(kernel.registerCount(), static_cast<int>(ir.valueCount) + 1);
        const auto result = test::runKernel(kernel, points);
        for (size_t i = 0; i < points.size(); ++i) {
            const glm::vec3 expected = evaluateIr(ir, points[i]);
            for (int k = 0; k < 3; ++k) {
                if (std::isnan(expected[k])) {
                    ASSERT_TRUE(std::isnan(result.Ci[i][k])) << src;
                } else {
                    ASSERT_EQ(result.Ci[i][k], expected[k]) << src << "\npoint " << i << "\n"
                                                            << ir.dump();
                }
            }
        }
    }
}

TEST(Interpreter, ReusesRegisters) {
    // A long chain needs few live values at once.
    std::string src = "surface c() { float a = u;\n";
    for (int i = 0; i < 200; ++i) src += "a = sin(a) * v + " + std::to_string(i) + ".5;\n";
    src += "Ci = color(a); }";
    auto ast = compileShaderText("chain.sl", src);
    const ShaderKernel kernel(lowerShader(*ast, {}));
    EXPECT_GT(kernel.instructionCount(), 400u);
    EXPECT_LT(kernel.registerCount(), 220);  // ~200 constants, a handful of temporaries
}

TEST(Interpreter, CommonSubexpressionsAreShared) {
    auto a = compileShaderText("a.sl", "surface a() { Ci = color(noise(P * 3) + noise(P * 3)); }");
    const IrProgram ir = lowerShader(*a, {});
    int noises = 0;
    for (const Inst& inst : ir.insts) noises += inst.op == Op::Noise;
    EXPECT_EQ(noises, 1);
}

TEST(Interpreter, CountsInstructionsPerLane) {
    std::vector<ShadingPoint> points(10);
    const auto r = test::runShader("surface c() { Ci = color(u + v); }", points);
    // Two global loads and one add, for ten lanes.
    EXPECT_EQ(r.counters.instructions, 30u);
    EXPECT_EQ(r.counters.points, 10u);
}

TEST(Interpreter, ProductsFusedIntoTheirSumsRoundTwice) {
    // Products read once, by a sum, in every order and sign: each fused into its sum (one
    // pass, not two) and rounded before the sum as the two instructions round. With
    // u = v = 1 + 2^-12 and s = -(1 + 2^-11), u v rounds to 1 + 2^-11 (the 2^-24 is a tie
    // to even), so u v + s is exactly 0; a fused multiply-add would give 2^-24.
    const float u = 1.0f + 0x1p-12f;
    ShadingPoint p;
    p.u = p.v = u, p.s = -(1.0f + 0x1p-11f), p.t = 0.375f;
    std::vector<ShadingPoint> points(3, p);
    points[1].u = 0.1f, points[1].v = 0.3f, points[1].s = 0.7f;  // none exact
    points[2].u = -3.0f, points[2].v = 1e-8f, points[2].s = 1e30f;
    const std::string source =
        "surface f() { Ci = color(u * v + s, s + u * t, v * t - s);\n"
        "  Oi = color(s - u * s, (v * s - t) * t, 1); }";
    auto ast = compileShaderText("fused.sl", source);
    const ShaderKernel kernel(lowerShader(*ast, {}));
    // Five products, each fused into the one sum that reads it.
    EXPECT_EQ(kernel.passCount() + 5, kernel.instructionCount());
    const auto r = test::runKernel(kernel, points);
    auto times = [](float a, float b) {
        const volatile float product = a * b;  // rounded on its own
        return static_cast<float>(product);
    };
    for (size_t i = 0; i < points.size(); ++i) {
        const ShadingPoint& q = points[i];
        EXPECT_EQ(r.Ci[i].x, times(q.u, q.v) + q.s) << i;
        EXPECT_EQ(r.Ci[i].y, q.s + times(q.u, q.t)) << i;
        EXPECT_EQ(r.Ci[i].z, times(q.v, q.t) - q.s) << i;
        EXPECT_EQ(r.Oi[i].x, q.s - times(q.u, q.s)) << i;
        EXPECT_EQ(r.Oi[i].y, (times(q.v, q.s) - q.t) * q.t) << i;
    }
    EXPECT_EQ(r.Ci[0].x, 0.0f);
    // Counted as the program's instructions, fused or not.
    EXPECT_EQ(r.counters.instructions, kernel.instructionCount() * points.size());
}

}  // namespace
}  // namespace mpshade
