// Refinement by image tile (controller/tile_refiner.h) against shading in bands: a frame
// shaded per 2x2 pixels at 640x360, then every tile of it shaded again per pixel -- the
// same points a frame shaded per pixel shades in its bands. refine_ns_per_point (the
// passes' wall time over their points) beside band_ns_per_point (the per-pixel frame's own
// shading, in the same run) is what shading a point again in a tile costs against shading
// it in the first place.
#include <string>

#include <benchmark/benchmark.h>

#include "controller/multiphase_renderer.h"
#include "scene/scene.h"

namespace mpshade {
namespace {

void refineAll(benchmark::State& state, const char* path) {
    const Scene scene = loadScene(std::string(MPSHADE_SOURCE_DIR) + "/" + path);
    MultiphaseOptions options;
    options.frameBudgetSeconds = 1e6;  // refinement and fills never stop short
    options.refine.enabled = true;
    options.refine.until = 1.0;
    options.refine.tileSize = static_cast<int>(state.range(0));
    MultiphaseRenderer multi(scene, options);
    RenderOptions cheap;
    cheap.width = 640, cheap.height = 360;
    cheap.shadingRate = ShadingRate::Quad;
    RenderOptions pixel = cheap;
    pixel.shadingRate = ShadingRate::Pixel;
    FrameStats stats, bands;
    Image image;
    for (int frame = 0; frame < 3; ++frame) multi.renderFrame(frame, pixel, bands, image);
    multi.setRefineSteps({{ShadingRate::Pixel, 1.0f}});
    for (int frame = 1; frame < 3; ++frame) multi.renderFrame(frame, cheap, stats, image);
    double refineSeconds = 0.0, bandSeconds = 0.0;
    uint64_t refinePoints = 0, bandPoints = 0;
    int frame = 1;
    for (auto _ : state) {
        multi.setRefineSteps({});
        multi.renderFrame(frame, pixel, bands, image);
        multi.setRefineSteps({{ShadingRate::Pixel, 1.0f}});
        multi.renderFrame(frame, cheap, stats, image);
        refineSeconds += stats.refine.passSeconds;
        refinePoints += stats.refine.shadingPoints;
        bandSeconds += bands.dynamic.shadeSeconds;
        bandPoints += bands.shadedPoints;
        frame = 3 - frame;
    }
    state.counters["refine_ns_per_point"] = refinePoints ? 1e9 * refineSeconds / refinePoints : 0;
    state.counters["band_ns_per_point"] = bandPoints ? 1e9 * bandSeconds / bandPoints : 0;
    state.counters["refine_points"] = static_cast<double>(stats.refine.shadingPoints);
}

BENCHMARK_CAPTURE(refineAll, vase, "examples/vase/scene.json")
    ->Name("Refine/vase")
    ->Arg(16)
    ->Arg(32)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(refineAll, courtyard, "examples/courtyard/scene.json")
    ->Name("Refine/courtyard")
    ->Arg(16)
    ->Arg(32)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace mpshade
