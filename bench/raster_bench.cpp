// The rasterizer and the resolve alone, at 1280 x 720 or 640 x 360.
//
// Rasterizer: facets as the static phase makes them, a screen-filling grid of facets `cell`
// pixels across (two per cell, in clusters of 8 x 8 cells) over a tilted plane, so every
// facet is visible and their sizes are what dicing to a quarter-pixel flatness or half-pixel
// edges gives (about one or two facets per pixel).
//
// Sample layout: made from nothing, as a run's first frame makes it.
//
// Resolve: samples to pixels through the reconstruction filter, with every pixel's samples
// alike (one shading point a pixel, or one sample a pixel) or not, or every 2x2 block alike
// (one shading point per 2x2 pixels).
#include <cmath>
#include <string>

#include <benchmark/benchmark.h>

#include "phases/facet_rasterizer.h"
#include "phases/image.h"
#include "phases/sample_depth_test.h"
#include "phases/sample_pattern.h"

namespace mpshade {
namespace {

struct FacetGrid {
    FacetMesh mesh;
    WarpedVertices warped;
    SampleLayout layout;

    FacetGrid(int width, int height, int spp, float cell) : layout(width, height, spp, 1u) {
        const int nx = static_cast<int>(std::ceil(width / cell)) + 1;
        const int ny = static_cast<int>(std::ceil(height / cell)) + 1;
        warped.resize(static_cast<size_t>(nx) * ny);
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
                const size_t v = static_cast<size_t>(j) * nx + i;
                // A little jitter, so edges are not aligned with the sample grid.
                const float jx = 0.13f * std::sin(1.7f * i + 0.9f * j);
                const float jy = 0.11f * std::cos(1.3f * i - 0.7f * j);
                warped.x[v] = static_cast<int32_t>(std::lround(256.0f * (i + jx) * cell));
                warped.y[v] = static_cast<int32_t>(std::lround(256.0f * (j + jy) * cell));
                warped.invDepth[v] = 1.0f / (2.0f + 0.01f * (i + j));
            }
        constexpr int kClusterCells = 8;
        for (int cj = 0; cj < ny - 1; cj += kClusterCells)
            for (int ci = 0; ci < nx - 1; ci += kClusterCells) {
                FacetCluster cluster;
                cluster.firstFacet = static_cast<uint32_t>(mesh.positionIndex.size() / 3);
                for (int j = cj; j < std::min(cj + kClusterCells, ny - 1); ++j)
                    for (int i = ci; i < std::min(ci + kClusterCells, nx - 1); ++i) {
                        const uint32_t a = static_cast<uint32_t>(j * nx + i), b = a + 1,
                                       c = a + static_cast<uint32_t>(nx), d = c + 1;
                        for (uint32_t p : {a, c, b, b, c, d}) mesh.positionIndex.push_back(p);
                    }
                cluster.facetCount =
                    static_cast<uint32_t>(mesh.positionIndex.size() / 3) - cluster.firstFacet;
                mesh.clusters.push_back(cluster);
            }
        mesh.attributeIndex = mesh.positionIndex;
    }
};

void rasterGrid(benchmark::State& state, int spp, float cell) {
    const FacetGrid grid(640, 360, spp, cell);
    FacetRasterizer rasterizer;
    VisibilityBuffer visibility;
    RasterStats stats;
    const std::vector<RasterObject> objects = {{&grid.mesh, &grid.warped, nullptr, true}};
    for (auto _ : state) {
        rasterizer.rasterize(objects, grid.layout, 100.0f, RasterOptions{}, visibility, stats);
        benchmark::DoNotOptimize(visibility.facet.data());
    }
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * stats.facets));
    state.counters["facets"] = static_cast<double>(stats.facets);
    state.counters["fragments"] = static_cast<double>(stats.fragments);
    state.counters["facet_tile_pairs"] = static_cast<double>(stats.facetsBinned);
}

BENCHMARK_CAPTURE(rasterGrid, cell1_spp1, 1, 1.0f)
    ->Name("Raster/640x360/1spp/facets_1px")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(rasterGrid, cell1_spp4, 4, 1.0f)
    ->Name("Raster/640x360/4spp/facets_1px")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(rasterGrid, cell05_spp1, 1, 0.5f)
    ->Name("Raster/640x360/1spp/facets_half_px")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(rasterGrid, cell4_spp4, 4, 4.0f)
    ->Name("Raster/640x360/4spp/facets_4px")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The sample test alone, by kernel: rows of `n` samples (a facet n / 4 pixels across at 4
// spp), 8 rows a call, facets alternating between one that covers about half the samples
// and one behind it, over a 32 x 32-pixel tile's worth of rows. Items: samples.
void depthTest(benchmark::State& state, DepthTestKernel kernel, size_t n) {
    if (!depthTestKernelAvailable(kernel)) {
        state.SkipWithError("not available on this processor");
        return;
    }
    const size_t stride = 128 * 4, rows = 32;
    std::vector<int32_t> fx(rows * stride), fy(rows * stride);
    for (size_t r = 0; r < rows; ++r)
        for (size_t i = 0; i < stride; ++i) {
            fx[r * stride + i] = static_cast<int32_t>(64 * i + 37 * (i % 4));
            fy[r * stride + i] = static_cast<int32_t>(256 * r + 91 * (i % 4));
        }
    std::vector<float> inv(rows * stride, 0.0f);
    std::vector<uint32_t> object(rows * stride), facet(rows * stride);
    FacetEdges near{}, far{};
    // near: inside where lx > ly / 2 (half the box); far: everywhere, at a smaller 1 / depth.
    near.c[0] = 1.0, near.a[0] = 2.0, near.b[0] = -1.0;
    near.c[1] = near.c[2] = 1e9;
    near.zc = 0.5, near.zx = 1e-6, near.zy = -1e-6;
    far = near;
    far.c[0] = 1e9, far.zc = 0.25;
    uint32_t inside = 0, id = 0;
    for (auto _ : state) {
        for (size_t r = 0; r + 8 <= rows; r += 8) {
            const size_t at = r * stride;
            const SampleRows sr{fx.data() + at,
                                fy.data() + at,
                                inv.data() + at,
                                object.data() + at,
                                facet.data() + at,
                                8,
                                n,
                                stride};
            inside += depthTestRowsWith(kernel, sr, {(++id & 1) ? &near : &far, 0, 0, true, 1, id});
        }
        benchmark::DoNotOptimize(inside);
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * rows * n));
}

void registerDepthTests() {
    const std::pair<const char*, DepthTestKernel> kernels[] = {
        {"compiled", DepthTestKernel::Compiled},
        {"avx2", DepthTestKernel::Avx2},
        {"avx512", DepthTestKernel::Avx512}};
    for (const auto& [name, kernel] : kernels)
        for (size_t n : {1, 2, 3, 4, 8, 16, 64, 128, 512})
            benchmark::RegisterBenchmark(
                ("DepthTest/" + std::string(name) + "/row_" + std::to_string(n)).c_str(),
                [kernel = kernel, n](benchmark::State& s) { depthTest(s, kernel, n); });
}
const int depthTestsRegistered = (registerDepthTests(), 0);

// A run's sample layout made from nothing, as its first frame makes it: positions, filter
// taps and the per-pixel and per-block weights, their memory first touched.
void buildLayout(benchmark::State& state, int width, int height, int spp) {
    for (auto _ : state) {
        const SampleLayout layout(width, height, spp, 1u);
        benchmark::DoNotOptimize(&layout);
    }
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * width * height * spp);
}

BENCHMARK_CAPTURE(buildLayout, gallery, 480, 270, 4)
    ->Name("SampleLayout/480x270/4spp")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void resolveSamples(benchmark::State& state, int spp, bool uniform, bool quads = false) {
    const SampleLayout layout(1280, 720, spp, 1u);
    std::vector<float> rgba(layout.count() * 4);
    for (size_t i = 0; i < rgba.size(); ++i) rgba[i] = static_cast<float>(i % 97) / 97.0f;
    if (quads)  // one color a 2x2 block, as shading per 2x2 pixels gives
        for (int py = 0; py < layout.height(); ++py)
            for (int px = 0; px < layout.width(); ++px)
                for (int k = 0; k < spp; ++k)
                    for (int c = 0; c < 4; ++c)
                        rgba[4 * layout.index(px, py, k) + c] =
                            static_cast<float>((px / 2 + 7 * (py / 2) + c) % 97) / 97.0f;
    const std::vector<uint8_t> alike(static_cast<size_t>(layout.width()) * layout.height(),
                                     uniform ? 1 : 0);
    Image image;
    for (auto _ : state) {
        layout.resolve(rgba.data(), alike.data(), image, quads);
        benchmark::DoNotOptimize(image.rgba.data());
    }
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * layout.count()));
}

BENCHMARK_CAPTURE(resolveSamples, spp1, 1, true)
    ->Name("Resolve/1280x720/1spp")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(resolveSamples, spp1_quads, 1, true, true)
    ->Name("Resolve/1280x720/1spp_2x2_alike")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(resolveSamples, spp4, 4, false)
    ->Name("Resolve/1280x720/4spp")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(resolveSamples, spp4_alike, 4, true)
    ->Name("Resolve/1280x720/4spp_alike")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace mpshade
