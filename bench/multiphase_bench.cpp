// Multi-phase benchmarks: the fixed-point warp against a float (GLM) warp of the same
// vertices, rasterization, facets per covered pixel, and whole frames side by side with
// the reference renderer.
#include <memory>
#include <random>
#include <string>

#include <benchmark/benchmark.h>
#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>

#include "phases/facet_rasterizer.h"
#include "phases/fixed_point_warp.h"
#include "phases/multiphase_renderer.h"
#include "phases/reference_renderer.h"
#include "scene/scene.h"

namespace mpshade {
namespace {

std::string source(const std::string& relative) {
    return std::string(MPSHADE_SOURCE_DIR) + "/" + relative;
}

struct WarpData {
    Scene scene = loadScene(source("examples/vase/scene.json"));
    CameraState camera = cameraAt(scene, 0.0f, 480, 270);
    ObjectState state = objectAt(scene.objects[0], 0.0f, camera);
    FixedPointFormat format = FixedPointFormat::forBounds(surfaceBounds(*scene.objects[0].surface));
    std::vector<uint16_t> x, y, z;
    WarpData() {
        std::mt19937 rng(1);
        std::uniform_int_distribution<int> q(0, 65535);
        for (int i = 0; i < 1 << 20; ++i)
            x.push_back(uint16_t(q(rng))), y.push_back(uint16_t(q(rng))),
                z.push_back(uint16_t(q(rng)));
    }
};

void warpFixed(benchmark::State& state) {
    WarpData d;
    const FixedPointWarp warp(d.state.objectToWorld, d.camera, d.format);
    WarpedVertices out;
    for (auto _ : state) {
        warp.warp(d.x.data(), d.y.data(), d.z.data(), d.x.size(), out);
        benchmark::DoNotOptimize(out.x.data());
    }
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * d.x.size()));
}

// The same transform in float: dequantize, a 4x4 matrix, divide, round to 8 sub-pixel bits.
void warpFloat(benchmark::State& state) {
    WarpData d;
    const CameraState& c = d.camera;
    glm::mat4 view(1.0f);
    for (int k = 0; k < 3; ++k)
        view[k][0] = c.right[k], view[k][1] = c.up[k], view[k][2] = -c.forward[k];
    view[3] = glm::vec4(-glm::dot(c.right, c.eye), -glm::dot(c.up, c.eye),
                        glm::dot(c.forward, c.eye), 1.0f);
    const glm::mat4 m = view * d.state.objectToWorld;
    const float sx = c.width * 0.5f / (c.tanHalfFovY * c.aspect),
                sy = c.height * 0.5f / c.tanHalfFovY;
    std::vector<int32_t> ox(d.x.size()), oy(d.x.size());
    std::vector<float> depth(d.x.size());
    for (auto _ : state) {
        for (size_t i = 0; i < d.x.size(); ++i) {
            const glm::vec3 p = d.format.dequantize(d.x[i], d.y[i], d.z[i]);
            const glm::vec4 v = m * glm::vec4(p, 1.0f);
            const float w = -v.z;
            depth[i] = w;
            ox[i] = static_cast<int32_t>(256.0f * (c.width * 0.5f + sx * v.x / w));
            oy[i] = static_cast<int32_t>(256.0f * (c.height * 0.5f - sy * v.y / w));
        }
        benchmark::DoNotOptimize(ox.data());
        benchmark::DoNotOptimize(oy.data());
    }
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * d.x.size()));
}

// Steady-state frames: the static phase has run; frames stay in the range.
struct FrameFixture {
    Scene scene;
    std::unique_ptr<MultiphaseRenderer> multi;
    std::unique_ptr<ReferenceRenderer> reference;
    RenderOptions options;
    explicit FrameFixture(const char* path) : scene(loadScene(source(path))) {
        options.width = 240;
        options.height = 135;
        options.samplesPerPixel = 2;
    }
};

void frameReference(benchmark::State& state, const char* path) {
    FrameFixture f(path);
    f.reference = std::make_unique<ReferenceRenderer>(f.scene);
    FrameStats stats;
    for (auto _ : state)
        benchmark::DoNotOptimize(f.reference->renderFrame(1, f.options, stats).rgba.data());
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * stats.samples));
}

void frameMultiphase(benchmark::State& state, const char* path) {
    FrameFixture f(path);
    f.multi = std::make_unique<MultiphaseRenderer>(f.scene);
    FrameStats stats;
    f.multi->renderFrame(0, f.options, stats);  // the static phase
    uint64_t facets = 0, rasterized = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(f.multi->renderFrame(1, f.options, stats).rgba.data());
        facets += stats.facets;
        rasterized += stats.facetsRasterized;
    }
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * stats.samples));
    state.counters["facets"] = static_cast<double>(stats.facets);
    state.counters["static_runs_in_loop"] = stats.staticRuns;
    state.counters["raster_s"] = stats.rasterSeconds;
    state.counters["warp_s"] = stats.warpSeconds;
    state.counters["shade_s"] = stats.shadeSeconds;
}

// Facets per covered pixel, at the example's own size (a count, not a timing).
void facetsPerPixel(benchmark::State& state, const char* path) {
    FrameFixture f(path);
    f.options = RenderOptions{};
    f.multi = std::make_unique<MultiphaseRenderer>(f.scene);
    FrameStats stats;
    SampleBuffer samples;
    for (auto _ : state) samples = f.multi->renderSamples(0, f.options, stats);
    double covered = 0;
    for (size_t i = 3; i < samples.rgba.size(); i += 4) covered += samples.rgba[i];
    covered /= samples.spp;
    uint64_t visibleFacets = 0;
    for (size_t o = 0; o < f.scene.objects.size(); ++o)
        visibleFacets += f.multi->facets(o)->facetCount();
    state.counters["facets"] = static_cast<double>(visibleFacets);
    state.counters["covered_pixels"] = covered;
    state.counters["facets_per_covered_pixel"] = covered > 0 ? visibleFacets / covered : 0.0;
    // After this frame's culling (back faces, clusters off screen or facing away): the
    // facets the dynamic phase actually rasterized.
    state.counters["rasterized_per_covered_pixel"] = covered > 0 ? stats.facetsRasterized / covered : 0.0;
}

BENCHMARK(warpFixed)->Name("Warp/fixed")->Unit(benchmark::kMillisecond);
BENCHMARK(warpFloat)->Name("Warp/float")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(frameReference, vase, "examples/vase/scene.json")
    ->Name("Frame/vase/reference")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(frameMultiphase, vase, "examples/vase/scene.json")
    ->Name("Frame/vase/multiphase")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(frameReference, teapot, "examples/teapot/scene.json")
    ->Name("Frame/teapot/reference")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(frameMultiphase, teapot, "examples/teapot/scene.json")
    ->Name("Frame/teapot/multiphase")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(facetsPerPixel, vase, "examples/vase/scene.json")
    ->Name("FacetsPerPixel/vase")
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(facetsPerPixel, teapot, "examples/teapot/scene.json")
    ->Name("FacetsPerPixel/teapot")
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(facetsPerPixel, courtyard, "examples/courtyard/scene.json")
    ->Name("FacetsPerPixel/courtyard")
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace mpshade
