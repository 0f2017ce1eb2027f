// DynamicPhase::refine(): image tiles of a frame shaded cheaply, shaded again at a finer
// rate, come out bit for bit as a frame shaded at that rate throughout, the pixels around
// them untouched; the tiles done are a prefix of those asked, none started after the
// deadline; and tiles whose finer footprint reads tiles not resident fall back and say so.
#include <chrono>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "phases/dynamic_frame.h"
#include "test_support.h"

namespace mpshade {
namespace {

using test::Frame;
using test::kSpp;
using test::shadeWhole;

constexpr int kW = 64, kH = 36, kTile = 16;

// Tiles of `w` x `h` pixels over the image, row by row; the last row and column cut short.
std::vector<PixelRect> imageTiles(int w = kTile, int h = kTile) {
    std::vector<PixelRect> tiles;
    for (int y = 0; y < kH; y += h)
        for (int x = 0; x < kW; x += w)
            tiles.push_back({x, y, std::min(kW, x + w), std::min(kH, y + h)});
    return tiles;
}

bool inside(const PixelRect& r, int px, int py) {
    return px >= r.x0 && px < r.x1 && py >= r.y0 && py < r.y1;
}

// The samples of pixel (px, py) in a and b, bit for bit (all of them, or the first).
bool samePixel(const SampleBuffer& a, const SampleBuffer& b, const SampleLayout& layout, int px,
               int py, bool all) {
    const size_t first = layout.index(px, py, 0);
    for (size_t s = first; s < first + (all ? kSpp : 1); ++s)
        for (int k = 0; k < 4; ++k)
            if (a.rgba[4 * s + k] != b.rgba[4 * s + k]) return false;
    return true;
}

// Refines every tile of a frame of `f` shaded at `cheap` to `fine` and expects the frame
// shaded at `fine` throughout, bit for bit.
void expectRefinedAsShadedThere(Frame& f, const std::vector<PixelRect>& tiles) {
    for (const auto& [cheap, fine] : {std::pair{ShadingRate::Quad, ShadingRate::Sample},
                                      std::pair{ShadingRate::Quad, ShadingRate::Pixel},
                                      std::pair{ShadingRate::Pixel, ShadingRate::Sample}}) {
        DynamicPhase direct(f.scene);
        shadeWhole(f, direct, f.state, f.options(fine));
        DynamicPhase phase(f.scene);
        shadeWhole(f, phase, f.state, f.options(cheap));
        std::vector<TileRequest> missing;
        const RefineCounts counts = phase.refine(tiles, {fine, 1.0f}, missing);
        EXPECT_EQ(counts.tiles, tiles.size());
        EXPECT_TRUE(missing.empty());
        EXPECT_EQ(counts.probeFallbacks, 0u);
        EXPECT_EQ(counts.shadingPoints, direct.stats().shadingPoints);
        // The frame's own counts stay the cheap pass's.
        EXPECT_LT(phase.stats().shadingPoints, direct.stats().shadingPoints);
        const bool all = fine == ShadingRate::Sample;
        for (int py = 0; py < kH; ++py)
            for (int px = 0; px < kW; ++px)
                ASSERT_TRUE(samePixel(phase.samples(), direct.samples(), *f.layout, px, py, all))
                    << px << "," << py << " rate " << static_cast<int>(fine);
        Image refined, want;
        phase.resolveAgain(refined);
        direct.resolve(want);
        for (size_t k = 0; k < want.rgba.size(); ++k)
            ASSERT_NEAR(refined.rgba[k], want.rgba[k], 1e-6f) << k;
    }
}

TEST(DynamicRefine, EveryTileRefinedIsTheFrameShadedAtThatRate) {
    // The vase's shaders whole at each point: a tile's points shade as the frame's do, in
    // whatever order. Tiles cut short by the image's edges on the right and at the bottom.
    Frame direct(test::sourcePath("examples/vase/scene.json"), Representation::Facets, kW, kH);
    expectRefinedAsShadedThere(direct, imageTiles());
    // As shader maps (every tile they read resident): a probe shares its filter's setup
    // with the query before it when their footprints nearly agree (probe_batch.h), so a
    // point's result depends on its neighbour in the batch; tiles as wide as the image,
    // as tall as the bands, put the points in the frame's own order.
    Frame maps(test::sourcePath("examples/vase/scene.json"), Representation::ShaderMap, kW, kH);
    expectRefinedAsShadedThere(maps, imageTiles(kW, 4));
}

TEST(DynamicRefine, OnlyTheTilesAskedForChangeAndPassedDeadlinesStartNone) {
    Frame f(test::sourcePath("examples/vase/scene.json"), Representation::Facets, kW, kH);
    DynamicPhase direct(f.scene);
    shadeWhole(f, direct, f.state, f.options(ShadingRate::Sample));
    DynamicPhase cheap(f.scene);
    shadeWhole(f, cheap, f.state, f.options(ShadingRate::Pixel));
    DynamicPhase phase(f.scene);
    shadeWhole(f, phase, f.state, f.options(ShadingRate::Pixel));
    std::vector<TileRequest> missing;
    // A deadline already passed: nothing starts, nothing changes.
    const RefineCounts none = phase.refine(
        imageTiles(), {ShadingRate::Sample, 1.0f, std::chrono::steady_clock::now()}, missing);
    EXPECT_EQ(none.tiles, 0u);
    EXPECT_EQ(none.shadingPoints, 0u);
    EXPECT_EQ(phase.samples().rgba, cheap.samples().rgba);
    // Two tiles, one cut short by the image's edge, one in the middle of a row.
    const std::vector<PixelRect> some = {{48, 32, 64, 36}, {16, 16, 32, 32}};
    const RefineCounts counts = phase.refine(some, {ShadingRate::Sample, 1.0f}, missing);
    EXPECT_EQ(counts.tiles, 2u);
    EXPECT_EQ(counts.shadingPoints,
              [&] {  // every fragment of the two tiles' samples
                  uint64_t n = 0;
                  for (const PixelRect& r : some)
                      for (int py = r.y0; py < r.y1; ++py)
                          for (int px = r.x0; px < r.x1; ++px)
                              for (int k = 0; k < kSpp; ++k)
                                  n += phase.visibility().count[f.layout->index(px, py, k)];
                  return n;
              }());
    int refinedPixels = 0;
    for (int py = 0; py < kH; ++py)
        for (int px = 0; px < kW; ++px) {
            const bool refined = inside(some[0], px, py) || inside(some[1], px, py);
            refinedPixels += refined;
            if (refined)
                ASSERT_TRUE(samePixel(phase.samples(), direct.samples(), *f.layout, px, py, true))
                    << px << "," << py;
            else
                ASSERT_TRUE(samePixel(phase.samples(), cheap.samples(), *f.layout, px, py, false))
                    << px << "," << py;
        }
    EXPECT_EQ(refinedPixels, 16 * 4 + 16 * 16);
}

TEST(DynamicRefine, AFinerFootprintFallsBackToCoarserLevelsAndReportsTheTiles) {
    // Tiles filled for 2x2 shading only: per sample the probes ask for finer levels, read
    // coarser ones and hand the tiles back, and every result is finite.
    Frame f(test::sourcePath("examples/vase/scene.json"), Representation::ShaderMap, kW, kH);
    DynamicPhase phase(f.scene);
    shadeWhole(f, phase, f.state, f.options(ShadingRate::Quad));
    std::vector<TileRequest> missing;
    const RefineCounts counts = phase.refine(imageTiles(), {ShadingRate::Sample, 1.0f}, missing);
    EXPECT_EQ(counts.tiles, imageTiles().size());
    EXPECT_FALSE(missing.empty());
    EXPECT_GT(counts.probeFallbacks, 0u);
    EXPECT_LE(counts.probeFallbacks, counts.probes);
    for (float v : phase.samples().rgba) ASSERT_TRUE(std::isfinite(v));
}

}  // namespace
}  // namespace mpshade
