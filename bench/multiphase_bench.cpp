// Multi-phase benchmarks: the fixed-point warp against a float (GLM) warp of the same
// vertices, rasterization, facets per covered pixel, and whole frames side by side with
// the reference renderer.
#include <cstdlib>
#include <memory>
#include <random>
#include <string>

#include <benchmark/benchmark.h>
#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>

#include "controller/multiphase_renderer.h"
#include "controller/stage_limits.h"
#include "controller/tile_predictor.h"
#include "phases/facet_rasterizer.h"
#include "phases/fixed_point_warp.h"
#include "phases/reference_renderer.h"
#include "phases/worker_threads.h"
#include "scene/scene.h"

#include <tbb/global_control.h>

namespace mpshade {
namespace {

// MPSHADE_BENCH_THREADS=1 runs every parallel loop on the calling thread, for instruction
// counts that see all the work (callgrind's --toggle-collect follows one thread).
const std::unique_ptr<tbb::global_control> threadLimit = [] {
    const char* n = std::getenv("MPSHADE_BENCH_THREADS");
    return n ? std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                     std::stoul(n))
             : nullptr;
}();

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

// Steady-state frames at the example's own size and spp: the static phase has run (frame
// 0), then frames 1 and 2 are rendered in turn (their tiles filled before timing). The
// two alternate because a frame equal to the last one is a still view, replayed without
// warp, rasterization or probes (view_reuse.h): rendering one frame over and over times
// that replay, not a frame of a moving camera. A scene whose camera does hold still
// (lamplight) is replayed as render would replay it. The multi-phase figure is beside
// the reference's, in the same binary and run, on the same frames.
struct FrameFixture {
    Scene scene;
    std::unique_ptr<MultiphaseRenderer> multi;
    std::unique_ptr<ReferenceRenderer> reference;
    RenderOptions options;
    explicit FrameFixture(const char* path) : scene(loadScene(source(path))) {}
};

void frameReference(benchmark::State& state, const char* path) {
    FrameFixture f(path);
    f.reference = std::make_unique<ReferenceRenderer>(f.scene);
    FrameStats stats;
    Image image;  // reused frame to frame, as render and play do
    // Both frames once before timing: the first builds the ray scenes, and a run of one
    // timed iteration (a reference frame takes most of the minimum time) had counted it,
    // which more than doubled the vase's figure (624 ms against 280 steady at one thread).
    for (int warm : {2, 1}) f.reference->renderFrame(warm, f.options, stats, image);
    int frame = 1;
    for (auto _ : state) {
        f.reference->renderFrame(frame, f.options, stats, image);
        frame = 3 - frame;
        benchmark::DoNotOptimize(image.rgba.data());
    }
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * stats.samples));
}

// The timed loop's frame, in a function of its own so instruction counts can be taken of it
// alone: valgrind --tool=callgrind --toggle-collect='*steadyFrame*'.
// The image is reused frame to frame, as render and play reuse it.
__attribute__((noinline)) void steadyFrame(MultiphaseRenderer& multi, const RenderOptions& options,
                                           FrameStats& stats, Image& image, int frame) {
    multi.renderFrame(frame, options, stats, image);
}

void frameMultiphase(benchmark::State& state, const char* path, int representation, int rate) {
    FrameFixture f(path);
    MultiphaseOptions options;
    if (representation >= 0) options.representation = static_cast<Representation>(representation);
    if (rate >= 0) options.shadingRate = static_cast<ShadingRate>(rate);
    f.multi = std::make_unique<MultiphaseRenderer>(f.scene, options);
    FrameStats stats;
    f.multi->renderFrame(0, f.options, stats);  // the static phase
    f.multi->renderFrame(1, f.options, stats);  // frame 1's tiles
    f.multi->renderFrame(2, f.options, stats);  // frame 2's
    Image image;
    int frame = 1;
    for (auto _ : state) {
        steadyFrame(*f.multi, f.options, stats, image, frame);
        frame = 3 - frame;
        benchmark::DoNotOptimize(image.rgba.data());
    }
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * stats.samples));
    state.counters["facets"] = static_cast<double>(stats.dynamic.facets);
    state.counters["static_runs_in_loop"] = stats.staticWork.work.runs;
    state.counters["warp_ms"] = 1e3 * stats.dynamic.warpSeconds;
    state.counters["raster_ms"] = 1e3 * stats.dynamic.rasterSeconds;
    state.counters["shade_ms"] = 1e3 * stats.dynamic.shadeSeconds;
    state.counters["resolve_ms"] = 1e3 * stats.dynamic.resolveSeconds;
    state.counters["shading_points"] = static_cast<double>(stats.shadedPoints);
    state.counters["view_reused"] = stats.dynamic.viewReused ? 1.0 : 0.0;
    state.counters["probes_per_point"] =
        stats.shadedPoints ? static_cast<double>(stats.dynamic.probes) / stats.shadedPoints : 0.0;
    // Each stage in nanoseconds per sample per core (stage_limits.h), the last frame's.
    MachineLimits cores;
    cores.cores = workerThreads();  // the threads that ran the frame
    for (const StageCost& c : dynamicStageCosts({stats}, f.options.samplesPerPixel, cores))
        state.counters["ns_" + c.name.substr(0, c.name.find(' '))] = c.nsPerSample;
}

// Facets per covered pixel, at the example's own size (a count, not a timing): stored in
// the drawn representations, and rasterized after culling (facet-tile pairs).
void facetsPerPixel(benchmark::State& state, const char* path, int representation) {
    FrameFixture f(path);
    MultiphaseOptions options;
    if (representation >= 0) options.representation = static_cast<Representation>(representation);
    f.multi = std::make_unique<MultiphaseRenderer>(f.scene, options);
    FrameStats stats;
    SampleBuffer samples;
    for (auto _ : state) samples = f.multi->renderSamples(0, f.options, stats);
    double covered = 0;
    for (size_t i = 3; i < samples.rgba.size(); i += 4) covered += samples.rgba[i];
    covered /= samples.spp;
    state.counters["facets"] = static_cast<double>(stats.dynamic.facets);
    state.counters["covered_pixels"] = covered;
    state.counters["facets_per_covered_pixel"] = covered > 0 ? stats.dynamic.facets / covered : 0.0;
    state.counters["rasterized_per_covered_pixel"] =
        covered > 0 ? stats.dynamic.raster.facetsBinned / covered : 0.0;
}

// The prefetch prediction `play` runs in a frame's slack (TilePredictor::predict:
// the frame 3 ahead at a quarter of 640 x 360, one sample a pixel), over representations
// built for 640 x 360 with frame 1's tiles filled. Its cost decides how often a frame has
// room for it; it draws every facet of the full-size representations.
void predictAhead(benchmark::State& state, const char* path) {
    FrameFixture f(path);
    f.options.width = 640;
    f.options.height = 360;
    MultiphaseOptions options;
    f.multi = std::make_unique<MultiphaseRenderer>(f.scene, options);
    FrameStats stats;
    f.multi->renderFrame(0, f.options, stats);
    f.multi->renderFrame(1, f.options, stats);
    TilePredictor predictor(*f.multi);
    double seconds = 0.0;
    size_t tiles = 0;
    for (auto _ : state) tiles = predictor.predict(4, f.options, 4, seconds).size();
    state.counters["tiles_predicted"] = static_cast<double>(tiles);
    state.counters["facets"] = static_cast<double>(stats.dynamic.facets);
}

BENCHMARK(warpFixed)->Name("Warp/fixed")->Unit(benchmark::kMillisecond);
BENCHMARK(warpFloat)->Name("Warp/float")->Unit(benchmark::kMillisecond);

constexpr int kAuto = -1, kFacets = static_cast<int>(Representation::Facets),
              kMap = static_cast<int>(Representation::ShaderMap);
constexpr int kSceneRate = -1, kPerSample = static_cast<int>(ShadingRate::Sample),
              kPerPixel = static_cast<int>(ShadingRate::Pixel),
              kPerQuad = static_cast<int>(ShadingRate::Quad);

#define MPSHADE_FRAME_BENCH(name, path)                                          \
    BENCHMARK_CAPTURE(frameReference, name, path)                                \
        ->Name("Frame/" #name "/reference")                                      \
        ->Unit(benchmark::kMillisecond)                                          \
        ->UseRealTime();                                                         \
    BENCHMARK_CAPTURE(frameMultiphase, name, path, kAuto, kSceneRate)            \
        ->Name("Frame/" #name "/multiphase")                                     \
        ->Unit(benchmark::kMillisecond)                                          \
        ->UseRealTime();                                                         \
    BENCHMARK_CAPTURE(frameMultiphase, name##_sample, path, kAuto, kPerSample)   \
        ->Name("Frame/" #name "/multiphase_per_sample")                          \
        ->Unit(benchmark::kMillisecond)                                          \
        ->UseRealTime();                                                         \
    BENCHMARK_CAPTURE(frameMultiphase, name##_pixel, path, kAuto, kPerPixel)     \
        ->Name("Frame/" #name "/multiphase_per_pixel")                           \
        ->Unit(benchmark::kMillisecond)                                          \
        ->UseRealTime();                                                         \
    BENCHMARK_CAPTURE(frameMultiphase, name##_quad, path, kAuto, kPerQuad)       \
        ->Name("Frame/" #name "/multiphase_per_quad")                            \
        ->Unit(benchmark::kMillisecond)                                          \
        ->UseRealTime();                                                         \
    BENCHMARK_CAPTURE(frameMultiphase, name##_facets, path, kFacets, kSceneRate) \
        ->Name("Frame/" #name "/multiphase_facets")                              \
        ->Unit(benchmark::kMillisecond)                                          \
        ->UseRealTime();                                                         \
    BENCHMARK_CAPTURE(facetsPerPixel, name##_map, path, kMap)                    \
        ->Name("FacetsPerPixel/" #name "/shadermap")                             \
        ->Iterations(1)                                                          \
        ->Unit(benchmark::kMillisecond);                                         \
    BENCHMARK_CAPTURE(facetsPerPixel, name##_facets, path, kFacets)              \
        ->Name("FacetsPerPixel/" #name "/facets")                                \
        ->Iterations(1)                                                          \
        ->Unit(benchmark::kMillisecond)

BENCHMARK_CAPTURE(predictAhead, vase, "examples/vase/scene.json")
    ->Name("Predict/vase/640x360")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(predictAhead, courtyard, "examples/courtyard/scene.json")
    ->Name("Predict/courtyard/640x360")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

MPSHADE_FRAME_BENCH(vase, "examples/vase/scene.json");
MPSHADE_FRAME_BENCH(teapot, "examples/teapot/scene.json");
MPSHADE_FRAME_BENCH(courtyard, "examples/courtyard/scene.json");
MPSHADE_FRAME_BENCH(gallery, "examples/gallery/scene.json");
// A still camera, only a light moving: each frame after the first replays the last one's
// view (view_reuse.h), the case where the static part is largest.
MPSHADE_FRAME_BENCH(lamplight, "examples/vase/lamplight.json");
// The hard case of a 400 x 400 floor seen from 0.25 units above it, dollying along it.
MPSHADE_FRAME_BENCH(grazing_floor, "tests/data/scenes/grazing_floor.json");

}  // namespace
}  // namespace mpshade
