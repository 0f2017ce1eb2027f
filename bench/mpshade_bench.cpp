// mpshade-bench: Google Benchmark harness. items_per_second is the figure to read:
// samples/s for renderers, lanes/s (shaded points/s) for the interpreter.
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

// The factored shader's two parts over the same points: the static part (per map texel or
// facet vertex, rarely) and the dynamic part (per sample, every frame). Read the ratio of
// the dynamic part's time to the unfactored shader's (Interpreter/<shader>). The cut as the
// minimum cut makes it, every static value stored (storeAboveCost 0): the plastic's static
// part is then its diffuse light, the figure that sets FactorOptions::storeAboveCost.
void factoredPart(benchmark::State& state, const char* shaderName, bool dynamicPart) {
    VasePoints v;
    FactorOptions cut;
    cut.storeAboveCost = 0;
    const FactoredShader f = factorShader(*exampleShader(shaderName), v.binding(), cut);
    const ShaderKernel staticKernel(f.staticPart), dynamicKernel(f.dynamicPart);
    std::vector<std::vector<float>> tuple(f.staticPart.channelOutputs.size(),
                                          std::vector<float>(VasePoints::n));
    std::vector<float*> outChannels;
    std::vector<const float*> inChannels;
    for (auto& c : tuple) outChannels.push_back(c.data()), inChannels.push_back(c.data());
    v.out.channels = outChannels.data();
    v.in.channels = inChannels.data();
    if (dynamicPart) {
        std::vector<float> workspace;
        ShadingCounters counters;
        staticKernel.run(v.uniforms, v.in, VasePoints::n, v.out, workspace, counters);
    }
    runKernelBench(state, dynamicPart ? dynamicKernel : staticKernel, v);
    state.counters["channels"] = f.chosenWidth;
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
        ->Unit(benchmark::kMicrosecond);
MPSHADE_FACTOR_BENCH(marble)
MPSHADE_FACTOR_BENCH(wood)
MPSHADE_FACTOR_BENCH(brick)
MPSHADE_FACTOR_BENCH(rust_over_paint)
MPSHADE_FACTOR_BENCH(plastic)
#undef MPSHADE_FACTOR_BENCH
}  // namespace
}  // namespace mpshade

BENCHMARK_MAIN();
