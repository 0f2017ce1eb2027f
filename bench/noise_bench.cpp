// Procedural noise: fbm3 with six octaves (marble's) and snoise3 over points spread across
// many lattice cells, as a shader map's fill evaluates them, one point at a time and as the
// interpreter runs them, in lanes, by each build. items/s is points/s.
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "shading/noise.h"
#include "shading/noise_paths.h"

namespace mpshade {
namespace {

struct NoisePoints {
    static constexpr int kCount = 4096;
    std::vector<float> x, y, z, out;
    NoisePoints() : x(kCount), y(kCount), z(kCount), out(kCount) {
        std::mt19937 rng(11);
        std::uniform_real_distribution<float> uni(-40.0f, 40.0f);
        for (int i = 0; i < kCount; ++i) x[i] = uni(rng), y[i] = uni(rng), z[i] = uni(rng);
    }
};

void BM_NoiseOneByOne(benchmark::State& state) {
    NoisePoints p;
    const int octaves = static_cast<int>(state.range(0));
    for (auto _ : state) {
        for (int i = 0; i < NoisePoints::kCount; ++i)
            p.out[i] = octaves == 0 ? snoise3(p.x[i], p.y[i], p.z[i])
                                    : fbm3(p.x[i], p.y[i], p.z[i], octaves);
        benchmark::DoNotOptimize(p.out.data());
    }
    state.SetItemsProcessed(state.iterations() * NoisePoints::kCount);
}
BENCHMARK(BM_NoiseOneByOne)->Name("Noise/one_by_one")->Arg(0)->Arg(6);

// Arg 0: octaves (0: snoise3); arg 1: the build (NoisePath: 0 portable, 1 AVX2, 2 AVX-512
// with VBMI), skipped where the processor lacks it.
void BM_NoiseLanes(benchmark::State& state) {
    NoisePoints p;
    const int octaves = static_cast<int>(state.range(0));
    const auto path = static_cast<NoisePath>(state.range(1));
    if (!noisePathAvailable(path)) {
        state.SkipWithError("this processor lacks the instructions");
        return;
    }
    for (auto _ : state) {
        noiseLanesOn(path, p.x.data(), p.y.data(), p.z.data(), octaves,
                     octaves == 0 ? NoiseSum::Single : NoiseSum::Fbm, p.out.data(),
                     NoisePoints::kCount);
        benchmark::DoNotOptimize(p.out.data());
    }
    state.SetItemsProcessed(state.iterations() * NoisePoints::kCount);
}
BENCHMARK(BM_NoiseLanes)->Name("Noise/lanes")->ArgsProduct({{0, 6}, {0, 1, 2}});

}  // namespace
}  // namespace mpshade
