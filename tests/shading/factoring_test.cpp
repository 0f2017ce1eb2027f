// The factoring front end. The core property: running the static part, storing its
// n-tuple, and running the dynamic part gives what the unfactored shader gives, while the
// static part sees different values of every dynamic input than the dynamic part does
// (so a static part that wrongly read a dynamic input would be caught).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <set>
#include <sstream>

#include <gtest/gtest.h>
#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "geometry/error.h"
#include "geometry/ray_scene.h"
#include "scene/scene.h"
#include "scene/variability.h"
#include "shading/factoring.h"
#include "shading/lower.h"
#include "shading/shader_compiler.h"
#include "shading/shader_harness.h"
#include "test_support.h"

namespace mpshade {
namespace {

using test::ShadingPoint;

struct Instance {
    std::vector<ShadingPoint> points;
    ShadingUniforms uniforms;
    std::vector<float> params;
    std::vector<LightSample> lights;
};

// The same surface points, with every dynamic input (I, E, time, animated parameters,
// moving lights) drawn afresh; geometry and fixed lights are the same.
Instance makeInstance(const std::vector<ShadingPoint>& surface, const IrProgram& program,
                      const ShaderBinding& binding, std::mt19937& rng,
                      const SurfaceRayScene* occluder) {
    std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
    Instance inst;
    inst.points = surface;
    for (ShadingPoint& p : inst.points) {
        glm::vec3 I(uni(rng), uni(rng), uni(rng));
        p.I = glm::length(I) > 0.01f ? glm::normalize(I) : glm::vec3(0, 0, -1);
    }
    for (int k = 0; k < program.paramFloats; ++k) inst.params.push_back(2.0f * uni(rng));
    std::mt19937 fixedRng(1234);  // fixed lights: the same in every instance
    std::uniform_real_distribution<float> fixedUni(0.1f, 1.0f);
    for (const LightBinding& lb : binding.lights) {
        std::mt19937& r = lb.movesRelativeToObject || lb.animated ? rng : fixedRng;
        std::uniform_real_distribution<float>& d =
            lb.movesRelativeToObject || lb.animated ? uni : fixedUni;
        LightSample l;
        l.kind = lb.kind;
        l.color = glm::abs(glm::vec3(d(r), d(r), d(r))) + 0.1f;
        l.position = glm::vec3(3 * d(r), 3 + d(r), 3 * d(r));
        l.toLight = glm::normalize(glm::vec3(d(r), 1.0f, d(r)));
        inst.lights.push_back(l);
    }
    inst.uniforms.time = 3.0f * uni(rng);
    inst.uniforms.eye = glm::vec3(5 * uni(rng), 5 * uni(rng), 5 * uni(rng));
    inst.uniforms.params = inst.params;
    inst.uniforms.lights = inst.lights;
    inst.uniforms.occluder = occluder;
    return inst;
}

std::vector<ShadingPoint> surfacePoints(std::mt19937& rng, size_t n) {
    std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
    std::vector<ShadingPoint> pts(n);
    for (ShadingPoint& p : pts) {
        p.P = glm::vec3(2 * uni(rng), 2 * uni(rng), 2 * uni(rng));
        p.N = glm::normalize(glm::vec3(uni(rng), uni(rng) + 1.5f, uni(rng)));
        p.Ng = p.N;
        p.u = 0.5f + 0.5f * uni(rng), p.v = 0.5f + 0.5f * uni(rng);
        p.s = p.u, p.t = p.v;
        p.dPdu = glm::vec3(1, 0, uni(rng));
        p.dPdv = glm::vec3(0, uni(rng), -1);
    }
    return pts;
}

bool close(float a, float b) {
    if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b);
    if (std::isinf(a) || std::isinf(b)) return a == b;
    return std::fabs(a - b) <= 1e-5f * std::fmax(1.0f, std::fmax(std::fabs(a), std::fabs(b)));
}

// The minimum cut alone: every static value a dynamic operation needs is stored, however
// cheap to repeat (FactorOptions::storeAboveCost has tests of its own).
FactorOptions cutOnly() {
    FactorOptions o;
    o.storeAboveCost = 0;
    return o;
}

// Checks static-then-dynamic against the unfactored shader; returns the factoring.
FactoredShader expectExact(const ShaderAst& ast, const ShaderBinding& binding,
                           const std::string& what, const FactorOptions& options = cutOnly(),
                           int instances = 3) {
    static const Surface sphere = Sphere{1.0f};
    static const SurfaceRayScene occluder(sphere);
    const FactoredShader f = factorShader(ast, binding, options);
    const ShaderKernel original(lowerShader(ast, binding));
    const ShaderKernel staticKernel(f.staticPart), dynamicKernel(f.dynamicPart);
    EXPECT_EQ(static_cast<int>(f.staticPart.channelOutputs.size()), f.chosenWidth) << what;
    EXPECT_EQ(f.dynamicPart.channelInputs, f.chosenWidth) << what;
    std::mt19937 rng(42);
    const std::vector<ShadingPoint> surface = surfacePoints(rng, 300);
    // The static phase runs once, at other values of the dynamic inputs.
    const Instance representative = makeInstance(surface, f.analyzed, binding, rng, &occluder);
    std::vector<std::vector<float>> tuple;
    test::runKernel(staticKernel, representative.points, representative.uniforms, nullptr, &tuple);
    for (int i = 0; i < instances; ++i) {
        const Instance frame = makeInstance(surface, f.analyzed, binding, rng, &occluder);
        const auto expected = test::runKernel(original, frame.points, frame.uniforms);
        const auto got = test::runKernel(dynamicKernel, frame.points, frame.uniforms, &tuple);
        for (size_t p = 0; p < surface.size(); ++p) {
            for (int k = 0; k < 3; ++k) {
                if (!close(got.Ci[p][k], expected.Ci[p][k]) ||
                    !close(got.Oi[p][k], expected.Oi[p][k])) {
                    ADD_FAILURE() << what << ": point " << p << " component " << k << ": factored "
                                  << got.Ci[p][k] << " vs " << expected.Ci[p][k]
                                  << "\nstatic part:\n"
                                  << f.staticPart.dump() << "dynamic part:\n"
                                  << f.dynamicPart.dump();
                    return f;
                }
            }
        }
    }
    return f;
}

ShaderBinding everythingVaries(const ShaderAst& ast) {
    ShaderBinding b;
    // Int parameters count rays and octaves, which must stay constant.
    for (const ParamDecl& p : ast.params)
        if (p.type != ValueType::Int) b.params[p.name].kind = ParamBinding::Kind::Animated;
    b.lights.resize(3);
    b.lights[0].kind = LightKind::Ambient;
    b.lights[0].animated = b.lights[0].movesRelativeToObject = true;
    b.lights[1].kind = LightKind::Distant;
    b.lights[1].movesRelativeToObject = true;
    b.lights[2].kind = LightKind::Point;
    b.lights[2].animated = b.lights[2].movesRelativeToObject = true;
    return b;
}

ShaderBinding fixedLights() {
    ShaderBinding b;
    b.lights.resize(3);
    b.lights[0].kind = LightKind::Ambient;
    b.lights[0].color[0] = b.lights[0].color[1] = b.lights[0].color[2] = 0.2f;
    b.lights[1].kind = LightKind::Distant;
    b.lights[2].kind = LightKind::Point;
    return b;
}

TEST(Factoring, ExampleShadersAreExactForEveryExampleBinding) {
    int checked = 0;
    for (const char* scenePath : {"examples/vase/scene.json", "examples/teapot/scene.json",
                                  "examples/courtyard/scene.json"}) {
        const Scene scene = loadScene(test::sourcePath(scenePath));
        std::set<std::string> seen;
        for (const SceneObject& obj : scene.objects) {
            if (!seen.insert(obj.shaderName).second) continue;
            expectExact(*obj.shader, bindingOf(scene, obj),
                        std::string(scenePath) + " " + obj.name);
            ++checked;
        }
    }
    EXPECT_GE(checked, 7);
}

TEST(Factoring, ExampleShadersAreExactWhenEverythingVariesOrNothingDoes) {
    for (const auto& entry :
         std::filesystem::directory_iterator(test::sourcePath("examples/shaders"))) {
        auto ast = loadShaderFile(entry.path().string());
        expectExact(*ast, everythingVaries(*ast),
                    entry.path().filename().string() + " (everything varies)");
        const FactoredShader f =
            expectExact(*ast, fixedLights(), entry.path().filename().string() + " (fixed lights)");
        // With fixed lights every example has static work to save; the pattern-heavy ones
        // leave the dynamic part (the specular highlights) far cheaper than the static part.
        EXPECT_LT(f.dynamicCost, f.originalCost) << entry.path();
        const std::string name = entry.path().stem().string();
        if (name == "marble" || name == "wood" || name == "rust_over_paint") {
            EXPECT_LT(f.dynamicCost * 3, f.staticCost)
                << entry.path() << ": the dynamic part should be far cheaper";
        }
    }
}

TEST(Factoring, PatentExampleStoresTwoValuesNotThree) {
    // C = A1 + A2 + A3 * Kspec, with Kspec dynamic (col. 10 of the patent): the n-tuple
    // holds A1 + A2 and A3.
    auto ast = compileShaderText("patent.sl", R"(
        surface patent(float Kspec = 1) {
            float A1 = noise(P);
            float A2 = noise(P * 2);
            float A3 = noise(P * 3);
            Ci = color(A1 + A3 * Kspec + A2);
        })");
    ShaderBinding b;
    b.params["Kspec"].kind = ParamBinding::Kind::Animated;
    const FactoredShader f = expectExact(*ast, b, "patent example");
    EXPECT_EQ(f.naiveWidth, 3);
    EXPECT_EQ(f.chosenWidth, 2);
    FactorOptions plain = cutOnly();
    plain.reassociate = false;
    EXPECT_EQ(expectExact(*ast, b, "patent example, no reassociation", plain).chosenWidth, 3);
}

TEST(Factoring, ValuesUsedOnlyTogetherAreOneChannel) {
    // a * rim * b with rim dynamic: the product of the two noises is all the dynamic part
    // needs, so it is one channel, not two.
    auto together = compileShaderText("together.sl", R"(
        surface together() {
            float a = fbm(P * 4, 4);
            float b = noise(P * 3);
            float rim = pow(1 - max(0, dot(N, -I)), 3);
            Ci = color(a * rim * b);
        })");
    const FactoredShader f = expectExact(*together, {}, "together");
    EXPECT_EQ(f.naiveWidth, 2);
    EXPECT_EQ(f.chosenWidth, 1);
    // A constant colour times fbm times a noise, times a dynamic term: per component three
    // static products, but fbm times the noise is one value for all three.
    auto tinted = compileShaderText("tinted.sl", R"(
        surface tinted() {
            color c = color(0.8, 0.5, 0.2) * fbm(P * 2, 3);
            float a = noise(P * 5);
            Ci = c * dot(N, -I) * a;
        })");
    EXPECT_EQ(expectExact(*tinted, {}, "tinted").chosenWidth, 1);
    // Read both as a sum and as a product: the two are needed, and two are kept.
    auto both = compileShaderText("both.sl", R"(
        surface both() {
            float a = fbm(P * 4, 4);
            float b = noise(P * 3);
            float rim = pow(1 - max(0, dot(N, -I)), 3);
            Ci = color(a + rim + b) * a * b;
        })");
    EXPECT_EQ(expectExact(*both, {}, "both").chosenWidth, 2);
}

TEST(Factoring, MinimumCutPrefersTheNarrowerSideAndDoesNotRepeatExpensiveWork) {
    // Five noise values feed one static sum used dynamically: one float, not five.
    auto ast = compileShaderText("cut.sl", R"(
        surface cut() {
            float sum = noise(P) + noise(P * 2) * noise(P * 3) - noise(P * 5) / (1 + noise(P * 7));
            Ci = color(sum * time, sum, 0);
        })");
    const FactoredShader f = expectExact(*ast, {}, "cut");
    EXPECT_EQ(f.naiveWidth, 1);
    EXPECT_EQ(f.chosenWidth, 1);
    for (const Inst& inst : f.dynamicPart.insts) EXPECT_NE(inst.op, Op::Noise);
    // Three uses of one static noise, reached by cheap arithmetic: store the noise once and
    // repeat the cheap arithmetic.
    auto ast2 = compileShaderText("cut2.sl", R"(
        surface cut2() {
            float n = fbm(P, 4);
            Ci = color((n + 1) * time, (n * 2) * time, (n - 3) * time);
        })");
    const FactoredShader f2 = expectExact(*ast2, {}, "cut2");
    EXPECT_EQ(f2.naiveWidth, 3);
    EXPECT_EQ(f2.chosenWidth, 1);
}

TEST(Factoring, DiscontinuitiesOfTheGeometryAreStoredNotRepeated) {
    // Mortar lines from s alone, under a dynamic factor: s is geometry the dynamic phase
    // has, and step and fract are cheap, but repeated per shading point the lines would be
    // point-sampled. Stored, they are prefiltered with the n-tuple.
    auto ast = compileShaderText("lines.sl", R"(
        surface lines() {
            float line = step(0.9, fract(s * 8));
            float smooth = s * s + 0.5 * t;
            Ci = color(line * time, smooth * time, 0);
        })");
    const FactoredShader f = expectExact(*ast, {}, "lines");
    for (const Inst& inst : f.dynamicPart.insts) {
        EXPECT_NE(inst.op, Op::Step);
        EXPECT_NE(inst.op, Op::Fract);
    }
    EXPECT_EQ(f.chosenWidth, 1) << "the line is stored; the smooth term is repeated";
    FactorOptions repeat;
    repeat.storeDiscontinuities = false;
    const FactoredShader g = expectExact(*ast, {}, "lines, repeated", repeat);
    EXPECT_EQ(g.chosenWidth, 0);
    int steps = 0;
    for (const Inst& inst : g.dynamicPart.insts) steps += inst.op == Op::Step;
    EXPECT_EQ(steps, 1);
}

TEST(Factoring, AllStaticAndAllDynamic) {
    auto allStatic = compileShaderText(
        "s.sl", "surface s() { Ci = color(noise(P), fbm(P, 3), u); Oi = noise(P * 2); }");
    const FactoredShader s = expectExact(*allStatic, {}, "all static");
    // The dynamic part only reads channels (u is geometry the dynamic phase has).
    for (const Inst& inst : s.dynamicPart.insts)
        EXPECT_TRUE(inst.op == Op::Channel || inst.op == Op::Const || inst.op == Op::Global)
            << opName(inst.op);
    EXPECT_EQ(s.chosenWidth, 3);
    EXPECT_TRUE(s.dynamicLines.empty());

    auto allDynamic =
        compileShaderText("d.sl", "surface d() { Ci = color(noise(I * time), time, E[0]); }");
    const FactoredShader d = expectExact(*allDynamic, {}, "all dynamic");
    EXPECT_EQ(d.chosenWidth, 0);
    EXPECT_EQ(d.staticInstructions, 0);
    EXPECT_EQ(d.dynamicInstructions, d.originalInstructions);
}

TEST(Factoring, DynamicBranchesLoopsAndNaN) {
    auto branch = compileShaderText("b.sl", R"(
        surface b() {
            color c = 0;
            if (time > 0.5) { c = color(noise(P * 4)); } else { c = color(fbm(P, 3), 0, 1); }
            float acc = 0;
            for (int i = 1; i <= 3; i += 1) { acc += noise(P * i) * time; }
            Ci = c + acc + color(log(noise(P) - 2) + sqrt(time - 1), 1 / (time - time), pow(-2, time));
        })");
    const FactoredShader f = expectExact(*branch, {}, "branches and loops", cutOnly(), 6);
    for (const Inst& inst : f.dynamicPart.insts) {
        EXPECT_NE(inst.op, Op::Noise);
        EXPECT_NE(inst.op, Op::Fbm);
    }
    EXPECT_GT(f.chosenWidth, 0);
}

TEST(Factoring, OverridesBakeAndDynamic) {
    // bake() holds a view-dependent value fixed at the range's representative view.
    auto baked =
        compileShaderText("k.sl", "surface k() { Ci = color(bake(dot(N, -I)) * noise(P)); }");
    const FactoredShader fb = factorShader(*baked, {});
    EXPECT_EQ(fb.chosenWidth, 1);
    EXPECT_EQ(fb.dynamicInstructions, 1);  // read the channel: nothing else varies
    // dynamic() forces noise to be evaluated every frame.
    auto forced =
        compileShaderText("f.sl", "surface f() { Ci = color(dynamic(noise(P)) + fbm(P, 2)); }");
    const FactoredShader ff = expectExact(*forced, {}, "dynamic()");
    int noise = 0;
    for (const Inst& inst : ff.dynamicPart.insts) noise += inst.op == Op::Noise;
    EXPECT_EQ(noise, 1);
    EXPECT_EQ(ff.chosenWidth, 1);  // the fbm
}

TEST(Factoring, LightingSplitsPerLightAndPerBinding) {
    auto ast = compileShaderText(
        "l.sl", "surface l() { Ci = noise(P) * (ambient() + diffuse(N)) + specular(N, -I, 0.3); }");
    ShaderBinding b = fixedLights();
    b.lights[2].movesRelativeToObject = true;  // the point light moves
    const FactoredShader f = expectExact(*ast, b, "one fixed and one moving light");
    for (const Inst& inst : f.staticPart.insts)
        if (inst.op == Op::Diffuse) {
            EXPECT_EQ(inst.imm, 1) << "only the fixed distant light's diffuse is static";
        }
    int dynamicDiffuse = 0;
    for (const Inst& inst : f.dynamicPart.insts)
        dynamicDiffuse += inst.op == Op::Diffuse && inst.imm == 2;
    EXPECT_EQ(dynamicDiffuse, 1);
    // The same shader on a moving object: every positional light moves relative to it.
    const FactoredShader g = expectExact(*ast, everythingVaries(*ast), "moving object");
    for (const Inst& inst : g.staticPart.insts) EXPECT_NE(inst.op, Op::Diffuse);
    EXPECT_NE(f.chosenWidth, g.chosenWidth);
}

TEST(Factoring, ExplainsWhyEachLineIsDynamic) {
    auto ast = compileShaderText("why.sl",
                                 "surface why(float k = 1) {\n  float a = noise(P);\n  float b = a "
                                 "* k;\n  Ci = color(b);\n}");
    ShaderBinding b;
    b.params["k"].kind = ParamBinding::Kind::Animated;
    FactorOptions store;
    store.storeAboveCost = 0;  // one noise (40 units) would otherwise be repeated, not stored
    const FactoredShader f = factorShader(*ast, b, store);
    ASSERT_EQ(f.dynamicLines.size(), 1u);
    EXPECT_EQ(f.dynamicLines[0].line, 3);
    ASSERT_FALSE(f.dynamicLines[0].chain.empty());
    EXPECT_NE(f.dynamicLines[0].chain.back().find("parameter 'k' is animated"), std::string::npos);
    ASSERT_EQ(f.channels.size(), 1u);
    EXPECT_EQ(f.channels[0].name, "a");
    EXPECT_EQ(f.channels[0].line, 2);
}

TEST(Factoring, OverridesOutsideTheSourceAreCheckedAndApplied) {
    // plastic.sl with a fixed light: its 42 units of static diffuse are cheaper to repeat
    // than to read back, so nothing is stored -- unless the binding asks to store the
    // product at 10:13. Asking to store the whole sum (10:45, it holds the specular, which
    // the view reaches) is refused naming I; repeating the constant Cs (10:10) is refused;
    // repeating the parameter-free lit colour by name works like dynamic().
    auto ast = loadShaderFile(test::sourcePath("examples/shaders/plastic.sl"));
    ShaderBinding b = fixedLights();
    EXPECT_EQ(factorShader(*ast, b).chosenWidth, 0);
    auto with = [&](const char* text, FactoringOverride::Kind kind) {
        ShaderBinding o = b;
        FactoringOverride f;
        EXPECT_TRUE(parseFactoringOverride(text, kind, f)) << text;
        o.overrides.push_back(f);
        return o;
    };
    const FactoredShader stored = factorShader(*ast, with("10:13", FactoringOverride::Kind::Store));
    EXPECT_EQ(stored.chosenWidth, 3);
    EXPECT_TRUE(stored.warnings.empty());  // a store asked for is no idle bake()
    auto refused = [&](const char* text, FactoringOverride::Kind kind) {
        try {
            factorShader(*ast, with(text, kind));
            return std::string("accepted");
        } catch (const InputError& e) {
            return e.message();
        }
    };
    EXPECT_NE(refused("10:45", FactoringOverride::Kind::Store).find("cannot store '10:45': I,"),
              std::string::npos)
        << refused("10:45", FactoringOverride::Kind::Store);
    EXPECT_NE(refused("10:10", FactoringOverride::Kind::Repeat).find("is a constant"),
              std::string::npos);
    EXPECT_NE(refused("99:1", FactoringOverride::Kind::Repeat).find("names nothing"),
              std::string::npos);
    // By a variable's name: marble's vein mask m repeated every frame, as dynamic(m) would.
    auto marble = loadShaderFile(test::sourcePath("examples/shaders/marble.sl"));
    ShaderBinding mb = fixedLights();
    const int before = factorShader(*marble, mb).dynamicCost;
    FactoringOverride m;
    ASSERT_TRUE(parseFactoringOverride("m", FactoringOverride::Kind::Repeat, m));
    mb.overrides.push_back(m);
    EXPECT_GT(factorShader(*marble, mb).dynamicCost, before + 100);
    // P * scale (10:22, under the fbm) is free work on the frames' geometry: nothing to
    // repeat.
    ShaderBinding freeWork = fixedLights();
    FactoringOverride p;
    ASSERT_TRUE(parseFactoringOverride("10:22", FactoringOverride::Kind::Repeat, p));
    freeWork.overrides.push_back(p);
    try {
        factorShader(*marble, freeWork);
        ADD_FAILURE() << "repeating free work was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(e.message().find("cannot repeat '10:22': it is free work"), std::string::npos)
            << e.message();
    }
    FactoringOverride bad;
    EXPECT_FALSE(parseFactoringOverride("1:x", FactoringOverride::Kind::Store, bad));
    EXPECT_FALSE(parseFactoringOverride("a b", FactoringOverride::Kind::Store, bad));
    EXPECT_FALSE(parseFactoringOverride("0:3", FactoringOverride::Kind::Store, bad));
}

TEST(Factoring, ARepeatOverrideUndoesABakeForItsBindingAlone) {
    // bake() in the source applies to every binding; a binding that repeats the baked
    // variable (or names the bake() call) runs its argument every frame instead: nothing
    // stored, nothing baked, exact. The cause named is the override, not a dynamic().
    auto ast = compileShaderText("p.sl",
                                 "surface p(float scale = 1) {\n"
                                 "  float w = bake(0.5 + 0.5 * sin(6 * time));\n"
                                 "  Ci = color(w * noise(P)) * scale;\n}");
    const FactoredShader baked = factorShader(*ast, {});
    EXPECT_EQ(baked.bakedLines.size(), 1u);
    for (const char* name : {"w", "2:13"}) {
        ShaderBinding b;
        FactoringOverride o;
        ASSERT_TRUE(parseFactoringOverride(name, FactoringOverride::Kind::Repeat, o));
        b.overrides.push_back(o);
        const FactoredShader f = expectExact(*ast, b, name);
        EXPECT_TRUE(f.bakedLines.empty()) << name;
        int sines = 0;
        for (const Inst& inst : f.dynamicPart.insts) sines += inst.op == Op::Sin;
        EXPECT_EQ(sines, 1) << name;
        EXPECT_EQ(f.chosenWidth, 1) << name;  // noise(P) alone is stored
    }
    // Repeating the baked value as a whole keeps the bake (the binding asks to read it
    // every frame, not to compute it) and says so.
    auto onlyRead = compileShaderText("r.sl",
                                      "surface r() {\n"
                                      "  float w = bake(sin(time)) * 2;\n"
                                      "  Ci = color(w);\n}");
    ShaderBinding b;
    FactoringOverride o;
    ASSERT_TRUE(parseFactoringOverride("w", FactoringOverride::Kind::Repeat, o));
    b.overrides.push_back(o);
    const FactoredShader r = factorShader(*onlyRead, b);
    EXPECT_EQ(r.bakedLines.size(), 1u);
    bool named = false, kind = false;
    for (const DynamicLine& line : r.dynamicLines) {
        for (const std::string& step : line.chain)
            named = named || step.find("the binding repeats 'w'") != std::string::npos;
        for (const DynamicCause& c : line.causes) kind = kind || c.kind == "override";
    }
    EXPECT_TRUE(named);
    EXPECT_TRUE(kind);
}

TEST(Factoring, AnnotationsThatDoNothingAreWarnedOf) {
    // A bake() of noise(P) (static already) and a dynamic() of literals do nothing; the
    // bake() of time-dependent work does something and is not warned of.
    auto ast = compileShaderText("w.sl",
                                 "surface w() {\n"
                                 "  float a = bake(noise(P));\n"
                                 "  float b = dynamic(0.5 * 2);\n"
                                 "  float c = bake(sin(time));\n"
                                 "  Ci = color(a + b + c) * time;\n}");
    const FactoredShader f = factorShader(*ast, {});
    ASSERT_EQ(f.warnings.size(), 2u);
    EXPECT_EQ(f.warnings[0].rfind("2:13: bake() of a value already static", 0), 0u)
        << f.warnings[0];
    EXPECT_EQ(f.warnings[1].rfind("3:13: dynamic() of a constant does nothing", 0), 0u)
        << f.warnings[1];
}

TEST(Factoring, EveryInputOfALineIsACause) {
    // Line 2 depends on time and on the animated k: both are its causes, not the first found
    // alone. Line 3's cause is the dynamic() the author wrote, at its own column, not the fbm
    // under it. Line 4 adds the view and the moving light, whose specular I had made dynamic
    // first.
    auto ast = compileShaderText("m.sl",
                                 "surface m(float k = 1) {\n"
                                 "  float a = sin(time * 3) * k;\n"
                                 "  float b = dynamic(fbm(P * 4, 3));\n"
                                 "  Ci = color(a + b) + specular(N, -I, 0.3);\n}");
    ShaderBinding b;
    b.params["k"].kind = ParamBinding::Kind::Animated;
    b.lights.resize(1);
    b.lights[0].kind = LightKind::Point;
    b.lights[0].movesRelativeToObject = true;
    const FactoredShader f = factorShader(*ast, b);
    ASSERT_EQ(f.dynamicLines.size(), 3u);
    auto kinds = [](const DynamicLine& l) {
        std::vector<std::string> k;
        for (const DynamicCause& c : l.causes) k.push_back(c.kind + ":" + c.name);
        std::sort(k.begin(), k.end());
        return k;
    };
    EXPECT_EQ(kinds(f.dynamicLines[0]), (std::vector<std::string>{"parameter:k", "time:time"}));
    ASSERT_EQ(f.dynamicLines[1].causes.size(), 1u);
    EXPECT_EQ(f.dynamicLines[1].causes[0].kind, "annotation");
    EXPECT_EQ(f.dynamicLines[1].causes[0].line, 3);
    EXPECT_EQ(f.dynamicLines[1].causes[0].column, 13);
    EXPECT_NE(f.dynamicLines[1].chain.back().find("(line 3:13)"), std::string::npos)
        << f.dynamicLines[1].chain.back();
    EXPECT_EQ(
        kinds(f.dynamicLines[2]),
        (std::vector<std::string>{"annotation:", "light:", "parameter:k", "time:time", "view:I"}));
    for (const DynamicCause& c : f.dynamicLines[2].causes) {
        if (c.kind == "light") {
            EXPECT_EQ(c.index, 0);
        }
    }
}

TEST(Factoring, BakedLinesAreReportedAsBakedNotDynamic) {
    // Lines 2 and 3 are stored (bake), though I and time reach them: they are baked lines,
    // each naming the input it freezes, not dynamic ones. Line 4's specular shares line 2's
    // -I and is dynamic.
    auto ast = compileShaderText("rim.sl",
                                 "surface r(float rate = 2) {\n"
                                 "  float rim = bake(pow(1.0 - max(0.0, dot(N, -I)), 3.0));\n"
                                 "  float pulse = bake(0.5 + 0.5 * sin(time * rate));\n"
                                 "  Ci = color(rim * pulse) + specular(N, -I, 0.3);\n}");
    const FactoredShader f = factorShader(*ast, fixedLights());
    ASSERT_EQ(f.dynamicLines.size(), 1u);
    EXPECT_EQ(f.dynamicLines[0].line, 4);
    ASSERT_EQ(f.bakedLines.size(), 2u);
    EXPECT_EQ(f.bakedLines[0].line, 2);
    ASSERT_FALSE(f.bakedLines[0].chain.empty());
    EXPECT_NE(f.bakedLines[0].chain.back().find("I, the direction from the eye"),
              std::string::npos);
    EXPECT_EQ(f.bakedLines[1].line, 3);
    ASSERT_FALSE(f.bakedLines[1].chain.empty());
    EXPECT_NE(f.bakedLines[1].chain.back().find("time changes every frame"), std::string::npos);
    // The annotated source: line 2 baked, 3 baked, 4 repeated every frame (and static:
    // the stored colour it adds to).
    ASSERT_EQ(f.lineStages.size(), 3u);
    EXPECT_EQ(f.lineStages[0].line, 2);
    EXPECT_TRUE(f.lineStages[0].baked);
    EXPECT_FALSE(f.lineStages[0].repeated);
    EXPECT_TRUE(f.lineStages[1].baked);
    EXPECT_FALSE(f.lineStages[1].repeated);
    EXPECT_EQ(f.lineStages[2].line, 4);
    EXPECT_TRUE(f.lineStages[2].repeated);
    EXPECT_FALSE(f.lineStages[2].baked);
    // Work on another line that only a bake() reads runs in the static phase too.
    auto split = compileShaderText("ph.sl",
                                   "surface p(float rate = 2) {\n"
                                   "  float ph = time * rate;\n"
                                   "  float pulse = bake(sin(ph));\n"
                                   "  Ci = color(pulse) * noise(P * time);\n}");
    const FactoredShader g = factorShader(*split, fixedLights());
    ASSERT_EQ(g.dynamicLines.size(), 1u);
    EXPECT_EQ(g.dynamicLines[0].line, 4);
    ASSERT_EQ(g.bakedLines.size(), 1u);
    EXPECT_EQ(g.bakedLines[0].line, 3);
    // A bake of a static value freezes nothing: no baked line.
    auto still = compileShaderText("n.sl", "surface n() { Ci = color(bake(noise(P))) * time; }");
    EXPECT_TRUE(factorShader(*still, {}).bakedLines.empty());
}

// Random well-typed programs over random mixes of static and dynamic inputs, with
// branches, loops and lighting.
std::string randomShader(std::mt19937& rng, int statements) {
    std::vector<std::string> vars = {"u",    "v", "P[0]",     "N[1]", "I[2]",
                                     "time", "k", "noise(P)", "E[1]"};
    std::ostringstream src;
    src << "surface r(float k = 1, color tint = color(0.5, 0.25, 1)) {\n    color c = tint * "
           "diffuse(N);\n";
    auto pick = [&]() { return vars[rng() % vars.size()]; };
    static const char* kBinary[] = {"+", "-", "*"};
    for (int i = 0; i < statements; ++i) {
        const std::string name = "t" + std::to_string(i);
        std::string e;
        switch (rng() % 7) {
            case 0:
            case 1:
                e = pick() + " " + kBinary[rng() % 3] + " " + pick();
                break;
            case 2:
                e = "sin(" + pick() + ") + " + pick();
                break;
            case 3:
                e = "noise(point(" + pick() + ", " + pick() + ", 0.25))";
                break;
            case 4:
                e = "mix(" + pick() + ", " + pick() + ", " + pick() + ")";
                break;
            case 5:
                e = "fbm(P * " + pick() + ", 2)";
                break;
            case 6:
                e = "max(" + pick() + ", 0) * " + pick();
                break;
        }
        src << "    float " << name << " = " << e << ";\n";
        if (rng() % 4 == 0)
            src << "    if (" << pick() << " > " << pick() << ") { " << name << " += " << pick()
                << "; } else { c += color(" << pick() << "); }\n";
        if (rng() % 6 == 0)
            src << "    for (int j = 0; j < 2; j += 1) { " << name << " += " << pick()
                << " * j; }\n";
        vars.push_back(name);
    }
    src << "    Ci = c * " << vars.back() << " + color(" << pick() << ", " << pick() << ", "
        << pick() << ")"
        << " + specular(N, -I, 0.4) * " << pick() << ";\n    Oi = clamp(" << pick()
        << ", 0, 1);\n}\n";
    return src.str();
}

TEST(Factoring, RandomShadersFactorExactly) {
    std::mt19937 rng(2024);
    for (int i = 0; i < 80; ++i) {
        const std::string src = randomShader(rng, 4 + i % 12);
        auto ast = compileShaderText("random.sl", src);
        ShaderBinding b = fixedLights();
        if (i % 2) b.params["k"].kind = ParamBinding::Kind::Animated;
        if (i % 3 == 0) b.params["tint"].kind = ParamBinding::Kind::Animated;
        if (i % 5 == 0) b.lights[1].movesRelativeToObject = true;
        FactorOptions options;
        options.geometryInDynamicPhase = i % 4 != 0;
        // Both ways of keeping cheap static work: repeated by the dynamic part, or stored.
        if (i % 3 == 1) options.storeAboveCost = 0;
        expectExact(*ast, b, src, options);
        if (HasFailure()) break;
    }
}

}  // namespace

}  // namespace mpshade

namespace mpshade {
namespace {

TEST(Factoring, AStaticPartCheaperThanAProbeIsRepeatedNotStored) {
    // k is animated, so a * k is dynamic and the static part is what feeds it.
    auto factor = [](const std::string& staticExpr, int limit) {
        auto ast = compileShaderText("cheap.sl", "surface cheap(float k = 1) {\n  float a = " +
                                                     staticExpr + ";\n  Ci = color(a * k);\n}");
        ShaderBinding b;
        b.params["k"].kind = ParamBinding::Kind::Animated;
        FactorOptions options;
        options.storeAboveCost = limit;
        return factorShader(*ast, b, options);
    };
    // A sine and a cosine (8 units each), two scales and an add (1 each): 19 units.
    // Stored above the limit, repeated at it exactly.
    const std::string waves = "sin(u * 7) + cos(v * 5)";
    ASSERT_EQ(factor(waves, 0).staticCost, 19);
    const FactoredShader stored = factor(waves, 18);
    EXPECT_EQ(stored.chosenWidth, 1);
    EXPECT_EQ(stored.recomputedStaticCost, 0);
    const FactoredShader repeated = factor(waves, 19);
    EXPECT_EQ(repeated.chosenWidth, 0);
    EXPECT_EQ(repeated.recomputedStaticCost, stored.staticCost);
    EXPECT_EQ(repeated.staticCost, 0);
    EXPECT_EQ(repeated.dynamicCost, repeated.originalCost);
    EXPECT_EQ(repeated.dynamicPart.channelInputs, 0);
    // What only the static phase may do, or what would alias point-sampled, stays stored
    // however cheap: bake(), noise, a discontinuity, occlusion rays.
    EXPECT_EQ(factor("bake(u * 2)", 1000).chosenWidth, 1);
    EXPECT_EQ(factor("noise(P)", 1000).chosenWidth, 1);
    EXPECT_EQ(factor("step(0.5, sin(u * 9))", 1000).chosenWidth, 1);
    EXPECT_EQ(factor("occlusion(P, N, 1)", 1000).chosenWidth, 1);
}

TEST(Factoring, CheapChannelsAreRepeatedAndCostlyOnesStored) {
    // k is animated: the stored values are a noise pattern (fbm, 160 units) and the two
    // fixed lights' diffuse colour (2 x 30 units, and 3 adding the second to the first). Only the
    // diffuse colour is cheap to repeat; with a limit of 64 too, as each channel after the first
    // adds only its sums.
    auto ast = compileShaderText(
        "mixed.sl",
        "surface mixed(float k = 1) {\n  float a = fbm(P, 4);\n  color d = diffuse(N);\n"
        "  Ci = color(a * k) + d * k;\n}");
    ShaderBinding b = fixedLights();
    b.params["k"].kind = ParamBinding::Kind::Animated;
    const FactoredShader all = expectExact(*ast, b, "mixed, all stored", cutOnly());
    ASSERT_EQ(all.chosenWidth, 4);
    const FactoredShader some = expectExact(*ast, b, "mixed, cheap ones repeated", FactorOptions{});
    ASSERT_EQ(some.chosenWidth, 1) << some.staticPart.dump();
    EXPECT_EQ(some.recomputedStaticCost, 63);
    EXPECT_EQ(some.channels[0].op, Op::Fbm);
    EXPECT_EQ(some.recomputedStaticCost, all.staticCost - some.staticCost);
    EXPECT_EQ(some.dynamicCost, all.dynamicCost + some.recomputedStaticCost);
    FactorOptions tight;
    tight.storeAboveCost = 64;
    EXPECT_EQ(expectExact(*ast, b, "mixed, limit 64", tight).chosenWidth, 1);
}

}  // namespace
}  // namespace mpshade
