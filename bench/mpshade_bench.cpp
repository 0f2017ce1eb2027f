// mpshade-bench: Google Benchmark harness. items_per_second is the figure to read:
// samples/s for renderers, lanes/s (shaded points/s) for the interpreter.
#include <algorithm>
#include <memory>
#include <random>
#include <string>

#include <benchmark/benchmark.h>

#include "geometry/ray_scene.h"
#include "phases/reference_renderer.h"
#include "scene/scene.h"
#include "scene/scene_state.h"
#include "scene/variability.h"
#include "shading/factoring.h"
#include "shading/lighting.h"
#include "shading/shader_compiler.h"
#include "shading/shading_batch.h"

namespace mpshade {
namespace {

std::string source(const std::string& relative) {
    return std::string(MPSHADE_SOURCE_DIR) + "/" + relative;
}

// The reference renderer on frame 0 of an example, at a reduced size.
void referenceRenderer(benchmark::State& state, const char* scenePath) {
    const Scene scene = loadScene(source(scenePath));
    ReferenceRenderer renderer(scene);
    RenderOptions options;
    options.width = 240;
    options.height = 135;
    options.samplesPerPixel = 2;
    uint64_t samples = 0;
    FrameStats stats;
    for (auto _ : state) {
        Image image = renderer.renderFrame(0, options, stats);
        benchmark::DoNotOptimize(image.rgba.data());
        samples += stats.samples;
    }
    state.SetItemsProcessed(static_cast<int64_t>(samples));
    state.counters["instr_per_sample"] =
        static_cast<double>(stats.shaderInstructions) / static_cast<double>(stats.samples);
}

// 4096 points of the vase as its shaders see them at frame 0, structure of arrays, with
// the vase's uniforms (an ambient and a distant light, occlusion against the vase).
struct VasePoints {
    static constexpr size_t n = 4096;
    Scene scene;
    std::unique_ptr<SurfaceRayScene> rays;
    ShadingBatch batch;
    std::vector<LightSample> lights;
    ShadingInputs& in = batch.in;
    ShadingOutputs& out = batch.out;
    ShadingUniforms uniforms;

    VasePoints() : scene(loadScene(source("examples/vase/scene.json"))) {
        const SceneObject& vase = scene.objects[0];
        rays = std::make_unique<SurfaceRayScene>(*vase.surface);
        std::mt19937 rng(1);
        std::uniform_real_distribution<float> uni(0.0f, 1.0f);
        const CameraState camera = cameraAt(scene, 0.0f, 480, 270);
        const ObjectState st = objectAt(vase, 0.0f, camera);
        batch.resize(n, 0);
        for (size_t i = 0; i < n; ++i) {
            const ChartPoint at{
                static_cast<int>(rng() % static_cast<unsigned>(chartCount(*vase.surface))),
                uni(rng), uni(rng)};
            const SurfaceSample s = evaluate(*vase.surface, at);
            batch.setPoint(i, s, at, glm::normalize(s.P - st.eye));
        }
        lightsAt(scene, st, 0.0f, lights);
        uniforms.eye = st.eye;
        uniforms.lights = lights;
        uniforms.occluder = rays.get();
        uniforms.occlusionBias = 1e-4f * surfaceBounds(*vase.surface).diagonal();
    }

    // The example shader, bound as the vase binds its own shader (its parameters dropped).
    ShaderBinding binding() const {
        SceneObject bound = scene.objects[0];
        bound.params.clear();
        return bindingOf(scene, bound);
    }
};

std::shared_ptr<const ShaderAst> exampleShader(const char* name) {
    return loadShaderFile(source(std::string("examples/shaders/") + name + ".sl"));
}

void runKernelBench(benchmark::State& state, const ShaderKernel& kernel, VasePoints& v) {
    std::vector<float> workspace;
    ShadingCounters counters;
    enableFlushToZero();
    for (auto _ : state) {
        kernel.run(v.uniforms, v.in, VasePoints::n, v.out, workspace, counters);
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * VasePoints::n));
    state.counters["instructions"] = static_cast<double>(kernel.instructionCount());
}

// The whole unfactored shader per point: what the reference renderer runs.
void interpreter(benchmark::State& state, const char* shaderName) {
    VasePoints v;
    auto kernel = buildKernel(*exampleShader(shaderName), v.binding());
    runKernelBench(state, *kernel, v);
}

// An example shader factored as the minimum cut makes it, every static value stored
// (storeAboveCost 0), over the vase's points: its n-tuple (read and written in place)
// filled by its static part, as the dynamic part reads it.
struct FactoredVasePoints {
    VasePoints v;
    FactoredShader f;
    std::vector<std::vector<float>> tuple;
    std::vector<float*> outChannels;
    std::vector<const float*> inChannels;

    explicit FactoredVasePoints(const char* shaderName) {
        FactorOptions cut;
        cut.storeAboveCost = 0;
        f = factorShader(*exampleShader(shaderName), v.binding(), cut);
        tuple.assign(f.staticPart.channelOutputs.size(), std::vector<float>(VasePoints::n));
        for (auto& c : tuple) outChannels.push_back(c.data()), inChannels.push_back(c.data());
        v.out.channels = outChannels.data();
        v.in.channels = inChannels.data();
        std::vector<float> workspace;
        ShadingCounters counters;
        ShaderKernel(f.staticPart).run(v.uniforms, v.in, VasePoints::n, v.out, workspace, counters);
    }
};

// The factored shader's two parts over the same points: the static part (per map texel or
// facet vertex, rarely) and the dynamic part (per sample, every frame). Read the ratio of
// the dynamic part's time to the unfactored shader's (Interpreter/<shader>). With every
// static value stored, the plastic's static part is its diffuse light, the figure that sets
// FactorOptions::storeAboveCost.
void factoredPart(benchmark::State& state, const char* shaderName, bool dynamicPart) {
    FactoredVasePoints d(shaderName);
    runKernelBench(state, ShaderKernel(dynamicPart ? d.f.dynamicPart : d.f.staticPart), d.v);
    state.counters["channels"] = d.f.chosenWidth;
}

// The floor under any kernel that lights the dynamic part's points with the engine's lane
// formulas (shading/lighting.h): its light operations alone, each over the points in runs
// of the interpreter's width, arguments read where they lie (V = -I made beforehand, the
// roughness or exponent its constant). A native kernel of the same shader does this work
// and more, so Factored/<shader>/dynamic over this bounds from above how far the
// interpreter is from native code (docs/factoring.md).
void dynamicLightFloor(benchmark::State& state, const char* shaderName) {
    FactoredVasePoints d(shaderName);
    const IrProgram& program = d.f.dynamicPart;
    std::vector<float> constant(static_cast<size_t>(program.valueCount), 0.0f);
    for (const Inst& i : program.insts)
        if (i.op == Op::Const) constant[static_cast<size_t>(i.result)] = i.constant;
    constexpr size_t n = VasePoints::n;
    std::vector<float> view(3 * n), rgb(3 * n);
    for (size_t c = 0; c < 3; ++c)
        for (size_t i = 0; i < n; ++i) view[c * n + i] = -d.v.in.I[c][i];
    struct LightOp {
        Op op;
        int light;
        std::vector<float> param;
    };
    std::vector<LightOp> ops;
    for (const Inst& i : program.insts) {
        if (i.op != Op::Diffuse && i.op != Op::Specular && i.op != Op::Phong) continue;
        const float param =
            i.nargs > 9 ? constant[static_cast<size_t>(program.argsOf(i)[9])] : 0.0f;
        ops.push_back({i.op, i.imm, std::vector<float>(n, param)});
    }
    for (auto _ : state) {
        for (size_t first = 0; first < n; first += ShaderKernel::kLanes) {
            const int m = static_cast<int>(std::min<size_t>(ShaderKernel::kLanes, n - first));
            for (const LightOp& l : ops) {
                const float* args[10] = {d.v.in.P[0] + first,  d.v.in.P[1] + first,
                                         d.v.in.P[2] + first,  d.v.in.N[0] + first,
                                         d.v.in.N[1] + first,  d.v.in.N[2] + first,
                                         &view[first],         &view[n + first],
                                         &view[2 * n + first], l.param.data() + first};
                float* out[3] = {&rgb[first], &rgb[n + first], &rgb[2 * n + first]};
                shadeLight(l.op, d.v.lights[static_cast<size_t>(l.light)], args, out, m);
            }
        }
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * n));
    state.counters["light_ops"] = static_cast<double>(ops.size());
}

// marble.sl's dynamic part written by hand, over one run of up to the interpreter's width
// from `first`: Ci = the stored n-tuple + Ks specular(N, -I, roughness) by the binding's
// specular light, Oi = 1. Cloned for AVX2 as the interpreter's batch is, so both run
// eight lanes at a time.
__attribute__((target_clones("avx2", "default"))) void marbleRun(const ShadingInputs& in,
                                                                 const LightSample& light,
                                                                 size_t first, int m, size_t n,
                                                                 float* ci, float* oi) {
    constexpr float kKs = 0.5f, kRoughness = 0.25f;  // marble.sl's defaults
    constexpr int kLanes = ShaderKernel::kLanes;
    alignas(64) float view[3][kLanes], spec[3][kLanes], roughness[kLanes];
    for (int i = 0; i < m; ++i) roughness[i] = kRoughness;
    for (int c = 0; c < 3; ++c)
        for (int i = 0; i < m; ++i) view[c][i] = -in.I[c][first + i];
    const float* args[10] = {in.P[0] + first, in.P[1] + first, in.P[2] + first, in.N[0] + first,
                             in.N[1] + first, in.N[2] + first, view[0],         view[1],
                             view[2],         roughness};
    float* out[3] = {spec[0], spec[1], spec[2]};
    shadeLight(Op::Specular, light, args, out, m);
    for (size_t c = 0; c < 3; ++c) {
        const float* tuple = in.channels[c] + first;
        float* o = ci + c * n + first;
        float* a = oi + c * n + first;
        for (int i = 0; i < m; ++i) o[i] = tuple[i] + kKs * spec[c][i], a[i] = 1.0f;
    }
}

// marbleRun over the vase's points, checked against the interpreter's result (the same
// operations in the same order, so the same bits) before timing.
void nativeMarbleDynamic(benchmark::State& state) {
    FactoredVasePoints d("marble");
    const IrProgram& program = d.f.dynamicPart;
    int light = -1, specularOps = 0;
    for (const Inst& i : program.insts)
        if (i.op == Op::Specular) light = i.imm, ++specularOps;
    if (specularOps != 1) return state.SkipWithError("marble's dynamic part changed");
    constexpr size_t n = VasePoints::n, kLanes = ShaderKernel::kLanes;
    std::vector<float> ci(3 * n), oi(3 * n);
    const LightSample& specularLight = d.v.lights[static_cast<size_t>(light)];
    auto run = [&] {
        for (size_t first = 0; first < n; first += kLanes)
            marbleRun(d.v.in, specularLight, first, static_cast<int>(std::min(kLanes, n - first)),
                      n, ci.data(), oi.data());
    };
    enableFlushToZero();
    run();
    std::vector<float> workspace;
    ShadingCounters counters;
    ShaderKernel(program).run(d.v.uniforms, d.v.in, n, d.v.out, workspace, counters);
    for (size_t c = 0; c < 3; ++c)
        for (size_t i = 0; i < n; ++i)
            if (ci[c * n + i] != d.v.out.Ci[c][i] || oi[c * n + i] != d.v.out.Oi[c][i])
                return state.SkipWithError("the native marble kernel differs from the interpreter");
    for (auto _ : state) {
        run();
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * n));
}

BENCHMARK_CAPTURE(referenceRenderer, vase, "examples/vase/scene.json")
    ->Name("Reference/vase")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(referenceRenderer, teapot, "examples/teapot/scene.json")
    ->Name("Reference/teapot")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(referenceRenderer, courtyard, "examples/courtyard/scene.json")
    ->Name("Reference/courtyard")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(interpreter, marble, "marble")
    ->Name("Interpreter/marble")
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(interpreter, wood, "wood")
    ->Name("Interpreter/wood")
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(interpreter, brick, "brick")
    ->Name("Interpreter/brick")
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(interpreter, rust_over_paint, "rust_over_paint")
    ->Name("Interpreter/rust_over_paint")
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(interpreter, plastic, "plastic")
    ->Name("Interpreter/plastic")
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(interpreter, patina_bronze, "patina_bronze")
    ->Name("Interpreter/patina_bronze")
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(interpreter, weathered_stone, "weathered_stone")
    ->Name("Interpreter/weathered_stone")
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace mpshade

namespace mpshade {
namespace {
#define MPSHADE_FACTOR_BENCH(name)                               \
    BENCHMARK_CAPTURE(factoredPart, name##_static, #name, false) \
        ->Name("Factored/" #name "/static")                      \
        ->Unit(benchmark::kMicrosecond);                         \
    BENCHMARK_CAPTURE(factoredPart, name##_dynamic, #name, true) \
        ->Name("Factored/" #name "/dynamic")                     \
        ->Unit(benchmark::kMicrosecond);                         \
    BENCHMARK_CAPTURE(dynamicLightFloor, name, #name)            \
        ->Name("Factored/" #name "/dynamic_light_floor")         \
        ->Unit(benchmark::kMicrosecond);
MPSHADE_FACTOR_BENCH(marble)
MPSHADE_FACTOR_BENCH(wood)
MPSHADE_FACTOR_BENCH(brick)
MPSHADE_FACTOR_BENCH(rust_over_paint)
MPSHADE_FACTOR_BENCH(plastic)
MPSHADE_FACTOR_BENCH(patina_bronze)
MPSHADE_FACTOR_BENCH(weathered_stone)
#undef MPSHADE_FACTOR_BENCH
BENCHMARK(nativeMarbleDynamic)->Name("Native/marble/dynamic")->Unit(benchmark::kMicrosecond);
}  // namespace
}  // namespace mpshade

BENCHMARK_MAIN();
