// Procedural noise: fbm3 with six octaves (marble's) and snoise3 over points spread across
// many lattice cells, as a shader map's fill evaluates them, one point at a time and as the
// interpreter runs them, in lanes. items/s is points/s.
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "shading/noise.h"

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

void BM_NoiseLanes(benchmark::State& state) {
    NoisePoints p;
    const int octaves = static_cast<int>(state.range(0));
    for (auto _ : state) {
        if (octaves == 0)
            snoise3Lanes(p.x.data(), p.y.data(), p.z.data(), p.out.data(), NoisePoints::kCount);
        else
            fbm3Lanes(p.x.data(), p.y.data(), p.z.data(), octaves, p.out.data(),
                      NoisePoints::kCount);
        benchmark::DoNotOptimize(p.out.data());
    }
    state.SetItemsProcessed(state.iterations() * NoisePoints::kCount);
}
BENCHMARK(BM_NoiseLanes)->Name("Noise/lanes")->Arg(0)->Arg(6);

}  // namespace
}  // namespace mpshade
