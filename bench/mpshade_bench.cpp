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
#include "shading/shader_compiler.h"

namespace mpshade {
namespace {

std::string source(const std::string& relative) {
    return std::string(MPSHADE_SOURCE_DIR) + "/" + relative;
}

// The reference renderer on frame 0 of an example, at a reduced size.
void referenceRenderer(benchmark::State& state, const char* scenePath) {
    const Scene scene = loadScene(source(scenePath));
    const ReferenceRenderer renderer(scene);
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

// One example shader over 4096 points of the vase, bound as in the vase scene (an
// ambient and a distant light, occlusion against the vase itself).
void interpreter(benchmark::State& state, const char* shaderName) {
    const Scene scene = loadScene(source("examples/vase/scene.json"));
    const SceneObject& vase = scene.objects[0];
    auto ast = loadShaderFile(source(std::string("examples/shaders/") + shaderName + ".sl"));
    SceneObject bound = vase;
    bound.params.clear();
    auto kernel = buildKernel(*ast, bindingOf(scene, bound));
    const SurfaceRayScene rays(*vase.surface);

    constexpr size_t n = 4096;
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> uni(0.0f, 1.0f);
    std::vector<std::vector<float>> rows(28, std::vector<float>(n));
    const CameraState camera = cameraAt(scene, 0.0f, 480, 270);
    const ObjectState st = objectAt(vase, 0.0f, camera);
    for (size_t i = 0; i < n; ++i) {
        const ChartPoint at{
            static_cast<int>(rng() % static_cast<unsigned>(chartCount(*vase.surface))), uni(rng),
            uni(rng)};
        const SurfaceSample s = evaluate(*vase.surface, at);
        const glm::vec3 I = glm::normalize(s.P - st.eye);
        for (int k = 0; k < 3; ++k) {
            rows[0 + k][i] = s.P[k], rows[3 + k][i] = s.N[k], rows[6 + k][i] = s.Ng[k];
            rows[9 + k][i] = s.dPdu[k], rows[12 + k][i] = s.dPdv[k], rows[15 + k][i] = I[k];
        }
        rows[18][i] = at.u, rows[19][i] = at.v, rows[20][i] = s.s, rows[21][i] = s.t;
    }
    ShadingInputs in;
    for (int k = 0; k < 3; ++k) {
        in.P[k] = rows[0 + k].data(), in.N[k] = rows[3 + k].data(), in.Ng[k] = rows[6 + k].data();
        in.dPdu[k] = rows[9 + k].data(), in.dPdv[k] = rows[12 + k].data(),
        in.I[k] = rows[15 + k].data();
    }
    in.u = rows[18].data(), in.v = rows[19].data(), in.s = rows[20].data(), in.t = rows[21].data();
    ShadingOutputs out;
    for (int k = 0; k < 3; ++k) out.Ci[k] = rows[22 + k].data(), out.Oi[k] = rows[25 + k].data();
    std::vector<LightSample> lights;
    lightsAt(scene, st, 0.0f, lights);
    std::vector<float> params;
    ShadingUniforms uniforms;
    uniforms.eye = st.eye;
    uniforms.lights = lights;
    uniforms.occluder = &rays;
    uniforms.occlusionBias = 1e-4f * surfaceBounds(*vase.surface).diagonal();
    std::vector<float> workspace;
    ShadingCounters counters;
    enableFlushToZero();
    for (auto _ : state) {
        kernel->run(uniforms, in, n, out, workspace, counters);
        benchmark::DoNotOptimize(rows[22].data());
    }
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * n));
    state.counters["instr_per_lane"] = static_cast<double>(kernel->instructionCount());
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

BENCHMARK_MAIN();
