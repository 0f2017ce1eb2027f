// Shader maps and probes: exact at texel centres, trilinear exact on linear functions,
// Feline close to EWA, residency fallback, half precision, degenerate footprints.
#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <set>

#include <cstring>

#include <gtest/gtest.h>

#include "shadermaps/half_float.h"
#include "shadermaps/probe.h"
#include "shadermaps/tile_pool.h"
#include "shadermaps/tile_table.h"
#include "shading/factoring.h"
#include "shading/noise.h"
#include "shading/shader_compiler.h"
#include "test_support.h"

namespace mpshade {
namespace {

// These maps hold what a test shader computes, however cheap it would be to repeat.
FactorOptions storeEverything() {
    FactorOptions o;
    o.storeAboveCost = 0;
    return o;
}

// A map of a shader's static part over a 4 x 4 plane; time keeps the rest dynamic.
struct MapFixture {
    Surface surface = Plane{4.0f, 4.0f};
    FactoredShader factored;
    std::unique_ptr<ShaderKernel> kernel;
    ShadingUniforms uniforms;

    explicit MapFixture(const char* source) {
        auto ast = compileShaderText("map.sl", source);
        factored = factorShader(*ast, {}, storeEverything());
        kernel = std::make_unique<ShaderKernel>(factored.staticPart);
    }

    // A map of every level at `resolution` texels a chart side, all filled.
    std::unique_ptr<ShaderMap> filledMap(int resolution) const {
        ShaderMapOptions options;
        options.resolution = resolution;
        auto map = std::make_unique<ShaderMap>(surface, *kernel, uniforms, options);
        map->fillLevels(0, map->levels() - 1);
        return map;
    }

    // The static program at one chart point, directly.
    std::vector<float> direct(float u, float v) const {
        const SurfaceSample g = evaluate(surface, {0, u, v});
        std::vector<float> rows(28),
            channels(static_cast<size_t>(kernel->program().channelOutputs.size()));
        ShadingInputs in;
        const float zero = 0.0f, I[3] = {0, 0, -1};
        for (int c = 0; c < 3; ++c)
            in.P[c] = &g.P[c], in.N[c] = &g.N[c], in.Ng[c] = &g.Ng[c], in.dPdu[c] = &g.dPdu[c],
            in.dPdv[c] = &g.dPdv[c], in.I[c] = &I[c];
        in.u = &u, in.v = &v, in.s = &g.s, in.t = &g.t;
        std::vector<float*> out(channels.size());
        for (size_t c = 0; c < channels.size(); ++c) out[c] = &channels[c];
        ShadingOutputs o;
        float sink[6];
        for (int c = 0; c < 3; ++c) o.Ci[c] = &sink[c], o.Oi[c] = &sink[3 + c];
        o.channels = out.data();
        std::vector<float> workspace;
        ShadingCounters counters;
        (void)zero;
        kernel->run(uniforms, in, 1, o, workspace, counters);
        return channels;
    }
};

const char* kNoiseShader =
    "surface n() { Ci = color(noise(P * 1.5), fbm(P * 0.7, 3), noise(P * 6)) * (1 + time); }";
// bake() keeps cheap functions of u and v in the map (otherwise the dynamic part would
// recompute them from the geometry it has).
const char* kLinearShader =
    "surface l() { Ci = color(bake(3 * u + 2 * v + 1), bake(u - v), bake(0.5 * v)) * (1 + time); }";

// Every texel of chart 0's `level` in two maps of three channels, within 1e-5 (float
// rounding: the same points summed in another order).
void expectSameTexels(const ShaderMap& a, const ShaderMap& b, int level) {
    const int res = a.resolution(level);
    for (int j = 0; j < res; ++j)
        for (int i = 0; i < res; ++i) {
            const TileKey key = a.tileOf(0, level, i, j);
            float x[3], y[3];
            a.texel(key, a.slotOf(key), i, j, x);
            b.texel(key, b.slotOf(key), i, j, y);
            for (int c = 0; c < 3; ++c)
                ASSERT_NEAR(x[c], y[c], 1e-5f) << "level " << level << ": " << i << "," << j;
        }
}

ProbeQuery query(float u, float v, float du, float dv, float aniso = 1.0f, float angle = 0.0f) {
    const float c = std::cos(angle), s = std::sin(angle);
    return {0, u, v, du * aniso * c, du * aniso * s, -dv * s, dv * c};
}

TEST(ShaderMap, ExactAtTexelCentres) {
    MapFixture f(kNoiseShader);
    const std::unique_ptr<ShaderMap> owned = f.filledMap(64);
    const ShaderMap& map = *owned;
    ASSERT_EQ(map.channels(), 3);
    ProbeOptions probe;
    probe.filter = ProbeFilter::Trilinear;
    for (int j = 0; j < 64; j += 7)
        for (int i = 0; i < 64; i += 5) {
            const float u = (i + 0.5f) / 64, v = (j + 0.5f) / 64;
            float out[3];
            const ProbeQuery q = query(u, v, 0.0f, 0.0f);
            probeShaderMap(map, probe, {&q, 1}, out);
            const std::vector<float> expected = f.direct(u, v);
            for (int c = 0; c < 3; ++c) ASSERT_NEAR(out[c], expected[c], 1e-6f) << i << "," << j;
        }
}

TEST(ShaderMap, TrilinearIsExactOnLinearFunctions) {
    MapFixture f(kLinearShader);
    const std::unique_ptr<ShaderMap> owned = f.filledMap(128);
    const ShaderMap& map = *owned;
    ProbeOptions probe;
    probe.filter = ProbeFilter::Trilinear;
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> pos(0.3f, 0.7f), size(0.0f, 4.0f);
    for (int k = 0; k < 2000; ++k) {
        // Footprints up to 2^4 level-0 texels: the coarse texels stay inside the chart.
        const float u = pos(rng), v = pos(rng), footprint = std::exp2(size(rng)) / 128.0f;
        const ProbeQuery q = query(u, v, footprint, footprint * 0.5f);
        float out[3];
        probeShaderMap(map, probe, {&q, 1}, out);
        ASSERT_NEAR(out[0], 3 * u + 2 * v + 1, 2e-5f);
        ASSERT_NEAR(out[1], u - v, 2e-5f);
        ASSERT_NEAR(out[2], 0.5f * v, 2e-5f);
    }
}

TEST(ShaderMap, FelineStaysCloseToEwa) {
    MapFixture f(kNoiseShader);
    const std::unique_ptr<ShaderMap> owned = f.filledMap(256);
    const ShaderMap& map = *owned;
    ProbeOptions feline, ewa;
    feline.filter = ProbeFilter::Feline;
    ewa.filter = ProbeFilter::EWA;
    ProbeOptions trilinear;
    trilinear.filter = ProbeFilter::Trilinear;
    std::mt19937 rng(2);
    std::uniform_real_distribution<float> pos(0.25f, 0.75f), angle(0.0f, 3.14159265f);
    double worst = 0.0, sum = 0.0, trilinearAt16 = 0.0, felineAt16 = 0.0;
    int n = 0;
    for (float aniso : {1.0f, 2.0f, 4.0f, 8.0f, 16.0f}) {
        for (int k = 0; k < 200; ++k) {
            const ProbeQuery q =
                query(pos(rng), pos(rng), 1.5f / 256.0f, 1.5f / 256.0f, aniso, angle(rng));
            float a[3], b[3], c[3];
            probeShaderMap(map, feline, {&q, 1}, a);
            probeShaderMap(map, ewa, {&q, 1}, b);
            probeShaderMap(map, trilinear, {&q, 1}, c);
            // The first channel is noise in [0, 1]: the difference is in those units.
            const double d = std::fabs(a[0] - b[0]);
            worst = std::max(worst, d);
            sum += d;
            ++n;
            if (aniso == 16.0f) felineAt16 += d, trilinearAt16 += std::fabs(c[0] - b[0]);
        }
    }
    // The bound documented in docs/shader-maps.md.
    EXPECT_LT(sum / n, 0.002);
    EXPECT_LT(worst, 0.015);
    // Trilinear blurs a long footprint to its long axis: clearly further from EWA.
    EXPECT_GT(trilinearAt16, 3.0 * felineAt16);
    RecordProperty("feline_vs_ewa_mean", std::to_string(sum / n));
    RecordProperty("feline_vs_ewa_max", std::to_string(worst));
    RecordProperty("trilinear_vs_ewa_mean_at_16", std::to_string(trilinearAt16 / 200));
}

TEST(ShaderMap, MissingTilesFallBackToCoarserLevels) {
    MapFixture f(kNoiseShader);
    ShaderMapOptions options;
    options.resolution = 256;
    options.alwaysResidentLevels = 3;  // 1x1, 2x2, 4x4
    ShaderMap map(f.surface, *f.kernel, f.uniforms, options);
    EXPECT_EQ(map.residentTiles(), 3u);
    ProbeOptions probe;
    probe.filter = ProbeFilter::Trilinear;
    const ProbeQuery q = query(0.4f, 0.6f, 0.0f, 0.0f);
    TileKey missing[8], touched[8];
    ProbeResidency residency{missing, 8};
    residency.touched = touched;
    residency.touchedCapacity = 8;
    float out[3], coarse[3];
    probeShaderMap(map, probe, {&q, 1}, out, &residency);
    EXPECT_GT(residency.fallbacks, 0u);
    ASSERT_GT(residency.count, 0u);
    EXPECT_EQ(missing[0].level, 0);
    // What was read: the 4x4 level's only tile (level 6 of 256).
    ASSERT_EQ(residency.touchedCount, 1u);
    EXPECT_EQ(touched[0].level, 6);
    // The answer is the 4x4 level's bilinear value.
    const ProbeQuery wide = query(0.4f, 0.6f, 64.0f / 256.0f, 64.0f / 256.0f);
    probeShaderMap(map, probe, {&wide, 1}, coarse);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(out[c], coarse[c], 1e-6f);
    // Filling what was missing removes the fallback.
    map.fill({missing, residency.count});
    ProbeResidency again{missing, 8};
    again.touched = touched;
    again.touchedCapacity = 8;
    probeShaderMap(map, probe, {&q, 1}, out, &again);
    EXPECT_EQ(again.fallbacks, 0u);
    ASSERT_EQ(again.touchedCount, 1u);
    EXPECT_EQ(touched[0].level, 0);
}

// A Feline line whose tile is missing falls back as a whole line to the coarser level's fast
// path; the per-tap path (forced by asking for the tiles read) falls back tap by tap. Both
// must read the same coarser texels with the same weights, and count the same fallbacks.
TEST(ShaderMap, FelineLinesFallBackLikeTheirTaps) {
    MapFixture f(kNoiseShader);
    ShaderMapOptions options;
    options.resolution = 256;
    options.alwaysResidentLevels = 3;  // levels 6-8
    ShaderMap map(f.surface, *f.kernel, f.uniforms, options);
    map.fillLevels(4, 4);  // 16 x 16 texels: one tile; levels 0-3 and 5 are missing
    ProbeOptions probe;
    probe.filter = ProbeFilter::Feline;
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> pos(0.05f, 0.95f), angle(0.0f, 3.14159f),
        size(1.0f, 6.0f);
    std::vector<ProbeQuery> queries;
    for (int i = 0; i < 200; ++i)
        queries.push_back(
            query(pos(rng), pos(rng), size(rng) / 256.0f, size(rng) / 256.0f, 4.0f, angle(rng)));
    std::vector<TileKey> missing(1 << 16), touched(1 << 16), missingSlow(1 << 16);
    ProbeResidency fast{missing.data(), missing.size()};
    ProbeResidency slow{missingSlow.data(), missingSlow.size()};
    slow.touched = touched.data();
    slow.touchedCapacity = touched.size();
    std::vector<float> a(queries.size() * 3), b(queries.size() * 3);
    probeShaderMap(map, probe, queries, a.data(), &fast);
    probeShaderMap(map, probe, queries, b.data(), &slow);
    for (size_t i = 0; i < a.size(); ++i) ASSERT_NEAR(a[i], b[i], 2e-6f) << "value " << i;
    EXPECT_GT(fast.fallbacks, 1000u);
    EXPECT_EQ(fast.fallbacks, slow.fallbacks);
    EXPECT_EQ(fast.bilinearProbes, slow.bilinearProbes);
    EXPECT_EQ(fast.missingProbes, slow.missingProbes);
    // The tiles a line reports are those its fast path reads: once they are filled, no
    // probe falls back. (Tap by tap, a tap in a tile's border reports the neighbour
    // holding that texel, so the two lists differ there.)
    for (size_t i = 0; i < fast.count; ++i) EXPECT_LT(missing[i].level, 4);
    map.fill({missing.data(), fast.count});
    ProbeResidency again{missing.data(), missing.size()};
    probeShaderMap(map, probe, queries, a.data(), &again);
    EXPECT_EQ(again.fallbacks, 0u);
    EXPECT_EQ(again.count, 0u);
    for (size_t i = 0; i < fast.count; ++i) EXPECT_LT(missing[i].level, 4);
}

// The levels a probe of footprint k level-0 texels (an isotropic query) reads, observed
// through the tiles it reports missing from a map holding only its 1 x 1 level.
std::set<int> levelsRead(const MapFixture& f, ProbeFilter filter, float k) {
    ShaderMapOptions options;
    options.resolution = 1024;
    options.alwaysResidentLevels = 1;
    ShaderMap map(f.surface, *f.kernel, f.uniforms, options);
    ProbeOptions probe;
    probe.filter = filter;
    probe.levelBlend = 1.0f;
    const ProbeQuery q = query(0.4f, 0.6f, k / 1024.0f, k / 1024.0f);
    TileKey missing[64];
    ProbeResidency residency{missing, 64};
    residency.stopAtMissing = true;  // each tap reports its own level, not the fallbacks
    float out[3];
    probeShaderMap(map, probe, {&q, 1}, out, &residency);
    std::set<int> levels;
    for (size_t i = 0; i < residency.count; ++i) levels.insert(missing[i].level);
    return levels;
}

TEST(ShaderMap, TheLevelAFootprintPicksIsPinned) {
    // log2 of the footprint picks the level: at exactly 2^L texels level L alone (the next
    // one would weigh nothing), a hair below it levels L - 1 and L.
    MapFixture f(kNoiseShader);
    for (ProbeFilter filter : {ProbeFilter::Trilinear, ProbeFilter::Feline}) {
        EXPECT_EQ(levelsRead(f, filter, 1.0f), std::set<int>({0})) << int(filter);
        EXPECT_EQ(levelsRead(f, filter, 1.01f), std::set<int>({0, 1})) << int(filter);
        for (int level = 1; level <= 4; ++level) {
            const float k = std::ldexp(1.0f, level);
            EXPECT_EQ(levelsRead(f, filter, k), std::set<int>({level}))
                << int(filter) << " at " << k;
            EXPECT_EQ(levelsRead(f, filter, k * 0.999f), std::set<int>({level - 1, level}))
                << int(filter) << " below " << k;
        }
    }
}

TEST(ShaderMap, AnisotropyCapWidensTheMinorAxisOrShortensTheMajor) {
    // Stripes across u, 8 level-0 texels a period; a footprint 1 texel across them (du/dx)
    // and 16 along them (dv/dy), capped at 2:1. Widening makes the minor axis 8 texels
    // (level 3, where a texel spans a whole period: the stripes average out); shortening
    // keeps level 0, where the stripes are resolved.
    MapFixture f("surface s() { Ci = color(bake(sin(u * 6.2831853 * 32)), 0, 0) * (1 + time); }");
    const std::unique_ptr<ShaderMap> owned = f.filledMap(256);
    const ShaderMap& map = *owned;
    for (AnisotropyCap cap : {AnisotropyCap::WidenMinor, AnisotropyCap::ShrinkMajor}) {
        ProbeOptions probe;
        probe.filter = ProbeFilter::Feline;
        probe.maxAnisotropy = 2.0f;
        probe.levelBlend = 1.0f;
        probe.cap = cap;
        for (int k = 0; k < 8; ++k) {
            const float u = (40.0f + k + 0.25f) / 32.0f * 0.5f + 0.01f, v = 0.5f;
            const ProbeQuery q{0, u, v, 1.0f / 256.0f, 0.0f, 0.0f, 16.0f / 256.0f};
            float out[3];
            probeShaderMap(map, probe, {&q, 1}, out);
            const float exact = f.direct(u, v)[0];
            if (cap == AnisotropyCap::WidenMinor)
                EXPECT_LT(std::fabs(out[0]), 0.15f) << "widened, at u = " << u;
            else
                EXPECT_NEAR(out[0], exact, 0.12f * std::fabs(exact) + 0.02f)
                    << "shortened, at u = " << u;
        }
        // The levels read, exactly: the minor axis's (1 texel: level 0) when shortened,
        // log2(16 / 2) = 3 when widened.
        ShaderMapOptions sparse;
        sparse.resolution = 256;
        sparse.alwaysResidentLevels = 1;
        ShaderMap empty(f.surface, *f.kernel, f.uniforms, sparse);
        TileKey missing[64];
        ProbeResidency residency{missing, 64};
        residency.stopAtMissing = true;
        const ProbeQuery q{0, 0.4f, 0.6f, 1.0f / 256.0f, 0.0f, 0.0f, 16.0f / 256.0f};
        float out[3];
        probeShaderMap(empty, probe, {&q, 1}, out, &residency);
        std::set<int> levels;
        for (size_t i = 0; i < residency.count; ++i) levels.insert(missing[i].level);
        EXPECT_EQ(levels, std::set<int>({cap == AnisotropyCap::ShrinkMajor ? 0 : 3}));
    }
}

TEST(ShaderMap, AnObliqueFootprintReadsNoFinerThanItsLevelAnisotropyAllows) {
    // ShrinkMajor at 2:1 with the finest level bounded at 8:1: a footprint 1 texel across
    // and 64 along reads level log2(64 / 8) = 3 (without the bound, level 0 of the minor
    // axis); exactly 8:1 is within the bound (level 0 alone); 8.5:1 just past it widens the
    // minor axis to 8.5 / 8 texels, log2 of which lies between levels 0 and 1. Rotating
    // the footprint (major along u) changes nothing.
    MapFixture f(kNoiseShader);
    ShaderMapOptions sparse;
    sparse.resolution = 256;
    sparse.alwaysResidentLevels = 1;
    ShaderMap empty(f.surface, *f.kernel, f.uniforms, sparse);
    auto levels = [&](float major, bool alongU, float bound) {
        ProbeOptions probe{ProbeFilter::Feline,        2.0f, 1.0f, 1.0f,
                           AnisotropyCap::ShrinkMajor, bound};
        TileKey missing[64];
        ProbeResidency residency{missing, 64};
        residency.stopAtMissing = true;
        const float a = 1.0f / 256.0f, b = major / 256.0f;
        const ProbeQuery q = alongU ? ProbeQuery{0, 0.4f, 0.6f, b, 0.0f, 0.0f, a}
                                    : ProbeQuery{0, 0.4f, 0.6f, a, 0.0f, 0.0f, b};
        float out[3];
        probeShaderMap(empty, probe, {&q, 1}, out, &residency);
        std::set<int> read;
        for (size_t i = 0; i < residency.count; ++i) read.insert(missing[i].level);
        return read;
    };
    for (const bool alongU : {false, true}) {
        EXPECT_EQ(levels(64.0f, alongU, 8.0f), std::set<int>({3})) << alongU;
        EXPECT_EQ(levels(64.0f, alongU, 0.0f), std::set<int>({0})) << alongU;
        EXPECT_EQ(levels(64.0f, alongU, 16.0f), std::set<int>({2})) << alongU;
        EXPECT_EQ(levels(8.0f, alongU, 8.0f), std::set<int>({0})) << alongU;
        EXPECT_EQ(levels(8.5f, alongU, 8.0f), std::set<int>({0, 1})) << alongU;
    }
}

TEST(ShaderMap, AlwaysResidentLevelsFilledUpFrontOrWhenFirstAsked) {
    // A plane is one chart; at 256 texels a side its six coarsest levels (32 x 32 .. 1 x 1)
    // are 4 + 5 tiles of 16 x 16.
    MapFixture f(kNoiseShader);
    ShaderMapOptions eagerOptions, lazyOptions;
    eagerOptions.resolution = lazyOptions.resolution = 256;
    lazyOptions.fillPinnedUpFront = false;
    const ShaderMap eager(f.surface, *f.kernel, f.uniforms, eagerOptions);
    EXPECT_EQ(eager.residentTiles(), 9u);
    ShaderMap lazy(f.surface, *f.kernel, f.uniforms, lazyOptions);
    EXPECT_EQ(lazy.residentTiles(), 0u);
    // A footprint of 16 level-0 texels reads level 4 (16 x 16 texels, one tile): missing,
    // reported, then filled -- and, being always resident, never offered for eviction.
    ProbeOptions probe;
    probe.filter = ProbeFilter::Trilinear;
    const ProbeQuery q = query(0.4f, 0.6f, 16.0f / 256.0f, 16.0f / 256.0f);
    TileKey missing[8];
    ProbeResidency residency{missing, 8};
    residency.stopAtMissing = true;
    float out[3];
    probeShaderMap(lazy, probe, {&q, 1}, out, &residency);
    ASSERT_EQ(residency.count, 1u);
    EXPECT_EQ(missing[0].level, 4);
    lazy.fill({missing, 1});
    EXPECT_EQ(lazy.residentTiles(), 1u);
    std::vector<TilePool::Held> evictable;
    lazy.pool()->evictable(~0u, evictable);
    EXPECT_TRUE(evictable.empty());
    // The same values as the eager map's.
    float a[3], b[3];
    probeShaderMap(lazy, probe, {&q, 1}, a);
    probeShaderMap(eager, probe, {&q, 1}, b);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(a[c], b[c]);
}

TEST(ShaderMap, HalfPrecisionErrorIsBounded) {
    MapFixture f(kNoiseShader);
    ShaderMapOptions full, half;
    full.resolution = half.resolution = 64;
    half.halfPrecision = true;
    ShaderMap a(f.surface, *f.kernel, f.uniforms, full), b(f.surface, *f.kernel, f.uniforms, half);
    a.fillLevels(0, a.levels() - 1);
    b.fillLevels(0, b.levels() - 1);
    EXPECT_LT(b.bytes(), a.bytes());
    ProbeOptions probe;
    probe.filter = ProbeFilter::Trilinear;
    for (int j = 0; j < 64; ++j)
        for (int i = 0; i < 64; ++i) {
            const ProbeQuery q = query((i + 0.5f) / 64, (j + 0.5f) / 64, 0.0f, 0.0f);
            float x[3], y[3];
            probeShaderMap(a, probe, {&q, 1}, x);
            probeShaderMap(b, probe, {&q, 1}, y);
            for (int c = 0; c < 3; ++c)
                ASSERT_LE(std::fabs(x[c] - y[c]),
                          std::ldexp(std::fabs(x[c]), -11) + std::ldexp(1.0f, -25));
        }
}

TEST(ShaderMap, HalfPrecisionKeepsFiniteValuesPastItsRangeFinite) {
    // (x + 2) 10^5 over the plane's x in [-2, 2]: 0 to 4 10^5, past 65504 beyond x = -1.34.
    // Stored as binary16 those texels hold 65504, not infinity; texels within the range
    // round as binary16 does; the float map keeps them all.
    MapFixture f("surface b() { Ci = color(bake((P[0] + 2) * 100000.0)) * (1 + time); }");
    ShaderMapOptions half;
    half.resolution = 16;
    half.halfPrecision = true;
    ShaderMap map(f.surface, *f.kernel, f.uniforms, half);
    map.fillLevels(0, 0);
    ProbeOptions probe;
    probe.filter = ProbeFilter::Trilinear;
    int saturated = 0;
    for (int i = 0; i < 16; ++i) {
        const float u = (i + 0.5f) / 16;
        const ProbeQuery q = query(u, 0.5f, 0.0f, 0.0f);
        float got[3];
        probeShaderMap(map, probe, {&q, 1}, got);
        const float exact = f.direct(u, 0.5f)[0];
        ASSERT_TRUE(std::isfinite(got[0])) << u;
        if (exact > 65504.0f) {
            EXPECT_EQ(got[0], 65504.0f) << u;
            ++saturated;
        } else {
            EXPECT_EQ(got[0], halfToFloat(floatToHalf(exact))) << u;
        }
    }
    EXPECT_GE(saturated, 12);  // texels of x > -1.34: 13 of 16 (their centres from x = -1.25)
}

TEST(ShaderMap, NoSeamsAcrossChartEdges) {
    // Bilinear probes between a chart's last texel centre and its edge interpolate towards
    // the border texel: evaluated on the neighbouring chart it continues the function;
    // clamped to the edge it does not. Compare both with direct evaluation.
    const Surface vase =
        SubdivSurface(loadObjCage(test::sourcePath("examples/vase/meshes/vase.obj")),
                      SubdivScheme::Catmark, "vase");
    auto ast = compileShaderText(
        "seam.sl", "surface seam() { Ci = color(noise(P * 3), fbm(P * 2, 2), 0) * (1 + time); }");
    const FactoredShader f = factorShader(*ast, {}, storeEverything());
    const ShaderKernel kernel(f.staticPart);
    ShaderMapOptions seamless, clamped;
    seamless.resolution = clamped.resolution = 16;
    clamped.seamless = false;
    ShaderMap a(vase, kernel, {}, seamless), b(vase, kernel, {}, clamped);
    a.fillLevels(0, 0);
    b.fillLevels(0, 0);
    ProbeOptions probe;
    probe.filter = ProbeFilter::Trilinear;
    const ChartAdjacency adjacency(vase);
    double errSeamless = 0.0, errClamped = 0.0;
    int n = 0;
    for (int chart = 0; chart < 88; ++chart) {
        if (adjacency.link(chart, 1).chart < 0) continue;
        for (float along = 0.1f; along < 0.9f; along += 0.1f) {
            const float u = 1.0f - 0.1f / 16.0f;  // beyond the last texel centre, towards the edge
            const ProbeQuery q{chart, u, along, 0, 0, 0, 0};
            float x[2], y[2];
            probeShaderMap(a, probe, {&q, 1}, x);
            probeShaderMap(b, probe, {&q, 1}, y);
            // Direct: the static program's first channel at that point.
            const SurfaceSample g = evaluate(vase, {chart, u, along});
            const float truth0 = noise3(3 * g.P.x, 3 * g.P.y, 3 * g.P.z);
            errSeamless += std::fabs(x[0] - truth0);
            errClamped += std::fabs(y[0] - truth0);
            ++n;
        }
    }
    ASSERT_GT(n, 300);
    EXPECT_LT(errSeamless, 0.6 * errClamped) << errSeamless / n << " vs " << errClamped / n;
    RecordProperty("edge_error_seamless", std::to_string(errSeamless / n));
    RecordProperty("edge_error_clamped", std::to_string(errClamped / n));
}

TEST(HalfFloat, RoundTripsAndRoundsToNearest) {
    EXPECT_EQ(halfToFloat(floatToHalf(1.0f)), 1.0f);
    EXPECT_EQ(halfToFloat(floatToHalf(-2.5f)), -2.5f);
    EXPECT_EQ(halfToFloat(floatToHalf(65504.0f)), 65504.0f);
    EXPECT_TRUE(std::isinf(halfToFloat(floatToHalf(1e6f))));
    EXPECT_TRUE(std::isnan(halfToFloat(floatToHalf(NAN))));
    EXPECT_EQ(halfToFloat(floatToHalf(std::ldexp(1.0f, -24))),
              std::ldexp(1.0f, -24));  // the smallest subnormal
    // Ties go to the even neighbour: 1 + 2^-11 lies halfway between 1 (even) and 1 + 2^-10
    // (odd); 1 + 3 2^-11 between 1 + 2^-10 (odd) and 1 + 2^-9 (even). Likewise in the
    // subnormal range: 1.5 2^-24 between 2^-24 (odd) and 2^-23 (even).
    EXPECT_EQ(halfToFloat(floatToHalf(1.0f + std::ldexp(1.0f, -11))), 1.0f);
    EXPECT_EQ(halfToFloat(floatToHalf(1.0f + 3.0f * std::ldexp(1.0f, -11))),
              1.0f + std::ldexp(1.0f, -9));
    EXPECT_EQ(halfToFloat(floatToHalf(-(1.0f + std::ldexp(1.0f, -11)))), -1.0f);
    EXPECT_EQ(halfToFloat(floatToHalf(1.5f * std::ldexp(1.0f, -24))), std::ldexp(1.0f, -23));
    EXPECT_EQ(halfToFloat(floatToHalf(2.5f * std::ldexp(1.0f, -24))), std::ldexp(1.0f, -23));
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> uni(-100.0f, 100.0f);
    for (int k = 0; k < 100000; ++k) {
        const float x = uni(rng);
        ASSERT_LE(std::fabs(halfToFloat(floatToHalf(x)) - x), std::ldexp(std::fabs(x), -11));
    }
}

TEST(Probe, DegenerateFootprintsGiveFiniteResults) {
    MapFixture f(kNoiseShader);
    const std::unique_ptr<ShaderMap> owned = f.filledMap(64);
    const ShaderMap& map = *owned;
    const float inf = INFINITY, nan = NAN;
    const ProbeQuery cases[] = {
        {0, 0.5f, 0.5f, 0, 0, 0, 0},         {0, 0.5f, 0.5f, nan, 0, 0, nan},
        {0, 0.5f, 0.5f, inf, inf, inf, inf}, {0, 0.5f, 0.5f, 1e-3f, 0, 0, 1e-9f},
        {0, nan, inf, 0.01f, 0, 0, 0.01f},   {0, 2.0f, -1.0f, 0.1f, 0.0f, 0.0f, 1e-7f},
    };
    for (ProbeFilter filter : {ProbeFilter::Trilinear, ProbeFilter::Feline, ProbeFilter::EWA}) {
        ProbeOptions options2;
        options2.filter = filter;
        for (const ProbeQuery& q : cases) {
            float out[3];
            probeShaderMap(map, options2, {&q, 1}, out);
            for (float x : out) ASSERT_TRUE(std::isfinite(x)) << static_cast<int>(filter);
        }
    }
}

TEST(Probe, FootprintsWithinASixteenthShareTheLastSetup) {
    // Feline keeps the last query's setup (level, line, weights) for a footprint within
    // 1/16 of it: at 1.06 times the footprint the answer is the first query's, bit for
    // bit, though alone it reads other levels' weights; at 1.07 it is its own. The
    // footprint sits where two levels blend (lod 3.47: 1.06 moves it to 3.55), so the
    // three answers differ.
    MapFixture f(kNoiseShader);
    const std::unique_ptr<ShaderMap> owned = f.filledMap(256);
    const ShaderMap& map = *owned;
    const ProbeOptions probe{ProbeFilter::Feline, 2.0f, 0.125f, 1.0f, AnisotropyCap::ShrinkMajor};
    const float base = std::exp2(3.47f) / 256.0f;
    auto at = [&](float scale) {
        return ProbeQuery{0, 0.37f, 0.61f, base * scale, 0.0f, 0.0f, base * scale};
    };
    auto probeAlone = [&](float scale, float* out) {
        const ProbeQuery q = at(scale);
        probeShaderMap(map, probe, {&q, 1}, out);
    };
    float first[3], near[3], far[3];
    probeAlone(1.0f, first);
    probeAlone(1.06f, near);
    probeAlone(1.07f, far);
    ASSERT_NE(first[0], near[0]);
    ASSERT_NE(first[0], far[0]);
    for (float scale : {1.06f, 1.07f}) {
        const ProbeQuery pair[2] = {at(1.0f), at(scale)};
        float out[6];
        probeShaderMap(map, probe, pair, out);
        for (int c = 0; c < 3; ++c) {
            EXPECT_EQ(out[c], first[c]);
            EXPECT_EQ(out[3 + c], scale == 1.06f ? first[c] : far[c]) << "at " << scale;
        }
    }
}

TEST(TileTable, FindsWhatWasInsertedAndForgetsWhatWasErased) {
    // Random keys in and out, checked against std::map; erasing from the middle of a
    // probe run must keep the keys after it findable (tombstones), and growing past
    // them must keep every live key.
    TileTable table;
    std::map<uint64_t, int32_t> truth;
    std::mt19937_64 rng(7);
    for (int step = 0; step < 20000; ++step) {
        const uint64_t key = rng() % 3000;  // collisions and re-insertions
        if (truth.count(key) && rng() % 2) {
            table.erase(key);
            truth.erase(key);
        } else if (!truth.count(key)) {
            const int32_t slot = static_cast<int32_t>(step);
            table.insert(key, slot);
            truth[key] = slot;
        }
        if (step % 997 == 0)
            for (uint64_t k = 0; k < 3000; ++k) {
                const auto it = truth.find(k);
                ASSERT_EQ(table.find(k), it == truth.end() ? -1 : it->second) << k;
            }
    }
    EXPECT_EQ(table.size(), truth.size());
}

TEST(ShaderMap, VirtualResolutionFillsOnlyWhatIsAsked) {
    // Level 0 of 2^20 texels a side: 2^32 tiles, of which one is asked for. The table holds
    // it and the always-resident levels; the texel centres hold the program's exact values.
    MapFixture f(kNoiseShader);
    ShaderMapOptions options;  // resolution 2^20 by default
    ShaderMap map(f.surface, *f.kernel, f.uniforms, options);
    ASSERT_EQ(map.resolution(0), 1 << 20);
    const size_t pinned = map.residentTiles();
    const TileKey key = map.tileOf(0, 0, 700000, 123456);
    map.fill({&key, 1});
    EXPECT_EQ(map.residentTiles(), pinned + 1);
    EXPECT_TRUE(map.resident(key));
    EXPECT_FALSE(map.resident(map.tileOf(0, 0, 700000 + 16, 123456)));
    const int i = 700000 + 3, j = 123456 + 5;
    float texel[3];
    map.texel(key, map.slotOf(key), i, j, texel);
    const std::vector<float> want = f.direct((i + 0.5f) / (1 << 20), (j + 0.5f) / (1 << 20));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(texel[c], want[static_cast<size_t>(c)], 1e-6f);
}

TEST(ShaderMap, BordersCopiedFromNeighboursEqualEvaluatedOnes) {
    // Tile (5, 5) of level 0 filled alone evaluates its whole 18 x 18 frame; filled after
    // its eight neighbours (one batch of nine), its 68 border texels come from them. The two
    // must hold the same bits, and only the 256 interior texels may run the program. In
    // float and in half storage (the copy moves the stored bits).
    MapFixture f(kNoiseShader);
    for (bool half : {false, true}) {
        SCOPED_TRACE(half ? "half" : "float");
        ShaderMapOptions options;
        options.resolution = 256;
        options.halfPrecision = half;
        ShaderMap alone(f.surface, *f.kernel, f.uniforms, options);
        ShaderMap among(f.surface, *f.kernel, f.uniforms, options);
        const TileKey key{0, 0, 5, 5};
        const FillStats pinned = alone.fillStats();  // the always-resident levels
        alone.fill({&key, 1});
        EXPECT_EQ(alone.fillStats().texelsCopied, pinned.texelsCopied);
        EXPECT_EQ(alone.fillStats().programRuns - pinned.programRuns, 324u);
        std::vector<TileKey> ring;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx)
                if (dx || dy)
                    ring.push_back(
                        {0, 0, static_cast<uint16_t>(5 + dx), static_cast<uint16_t>(5 + dy)});
        among.fill(ring);
        const FillStats ringStats = among.fillStats();
        among.fill({&key, 1});
        const FillStats after = among.fillStats();
        EXPECT_EQ(after.texelsCopied - ringStats.texelsCopied, 68u);
        EXPECT_EQ(after.programRuns - ringStats.programRuns, 256u);
        const size_t values = static_cast<size_t>(alone.stride() * alone.stride() * 3);
        if (half) {
            const uint16_t* a = alone.tileHalves(alone.slotOf(key));
            const uint16_t* b = among.tileHalves(among.slotOf(key));
            for (size_t x = 0; x < values; ++x) ASSERT_EQ(a[x], b[x]) << "value " << x;
        } else {
            const float* a = alone.tileFloats(alone.slotOf(key));
            const float* b = among.tileFloats(among.slotOf(key));
            for (size_t x = 0; x < values; ++x) ASSERT_EQ(a[x], b[x]) << "value " << x;
        }
        // A corner tile: its border beyond the plane's edge (no chart across) is evaluated,
        // the rest (right column, bottom row and the corner between) copied: 17 + 16 texels.
        const TileKey corner{0, 0, 0, 0};
        std::vector<TileKey> next = {{0, 0, 1, 0}, {0, 0, 0, 1}, {0, 0, 1, 1}};
        among.fill(next);
        const FillStats c0 = among.fillStats();
        among.fill({&corner, 1});
        EXPECT_EQ(among.fillStats().texelsCopied - c0.texelsCopied, 33u);
    }
}

TEST(ShaderMap, TilesBuiltFromTheirChildrenAreTheirBoxMean) {
    // A level-1 tile filled after its four children is their 2 x 2 mean, which is what
    // evaluating it with 2 x 2 supersamples gives (the same points): up to float rounding.
    MapFixture f(kNoiseShader);
    ShaderMapOptions options;
    options.resolution = 64;
    options.alwaysResidentLevels = 0;
    options.supersampleLimit = 2;
    ShaderMap built(f.surface, *f.kernel, f.uniforms, options);
    built.fillLevels(0, 0);
    built.fillLevels(1, 1);
    ShaderMap direct(f.surface, *f.kernel, f.uniforms, options);
    direct.fillLevels(1, 1);
    EXPECT_EQ(built.fillStats().tilesFromChildren, 4u);  // level 1: 32 x 32, four tiles
    EXPECT_EQ(direct.fillStats().tilesFromChildren, 0u);
    // Level 2 wants 4 x 4 samples, more than the limit allows: evaluated, never built from
    // level 1 (whose mean would be a wider box than a map without level 1 holds).
    built.fillLevels(2, 2);
    EXPECT_EQ(built.fillStats().tilesFromChildren, 4u);
    expectSameTexels(built, direct, 1);
}

TEST(ShaderMap, OneFillOfManyLevelsBuildsEachFromTheLevelBelowItFilled) {
    // Levels 0, 1 and 2 asked for in one call: level 1 waits for level 0 to be published and
    // is built from it; levels that cannot be built from children (level 2, over the
    // supersample limit) share a pass with it. The texels are those of separate fills.
    MapFixture f(kNoiseShader);
    ShaderMapOptions options;
    options.resolution = 64;
    options.alwaysResidentLevels = 0;
    options.supersampleLimit = 2;
    std::vector<TileKey> keys;
    for (uint16_t level = 0; level < 3; ++level) {
        const int tiles = std::max(1, (64 >> level) / options.tileSize);
        for (uint16_t ty = 0; ty < tiles; ++ty)
            for (uint16_t tx = 0; tx < tiles; ++tx) keys.push_back({0, level, tx, ty});
    }
    std::reverse(keys.begin(), keys.end());  // coarsest first: the fill orders them itself
    ShaderMap once(f.surface, *f.kernel, f.uniforms, options);
    once.fill(keys);
    EXPECT_EQ(once.fillStats().tiles, keys.size());
    EXPECT_EQ(once.fillStats().tilesFromChildren, 4u);  // level 1's four tiles
    ShaderMap apart(f.surface, *f.kernel, f.uniforms, options);
    for (int level = 0; level < 3; ++level) apart.fillLevels(level, level);
    for (int level = 0; level < 3; ++level) expectSameTexels(once, apart, level);
}

TEST(TilePool, MapsShareItAndEvictedSlotsAreReused) {
    MapFixture f(kNoiseShader);
    ShaderMapOptions options;
    options.resolution = 256;
    options.alwaysResidentLevels = 1;
    auto pool = std::make_shared<TilePool>(ShaderMap::tileBytesFor(options, 3));
    {
        ShaderMap a(f.surface, *f.kernel, f.uniforms, options, pool);
        ShaderMap b(f.surface, *f.kernel, f.uniforms, options, pool);
        EXPECT_EQ(pool->tilesHeld(), 2u);  // each map's 1 x 1 level
        std::vector<TileKey> keys;
        for (uint16_t t = 0; t < 8; ++t) keys.push_back({0, 0, t, 0});
        a.setUseStamp(5);
        a.fill(keys);
        b.fill({keys.data(), 2});
        EXPECT_EQ(pool->tilesHeld(), 12u);
        const size_t allocated = pool->bytesAllocated();
        // a's tiles were filled at stamp 5, b's at 0: before 3, only b's (not the pinned).
        std::vector<TilePool::Held> old;
        pool->evictable(3, old);
        ASSERT_EQ(old.size(), 2u);
        for (const TilePool::Held& h : old) {
            EXPECT_EQ(h.owner, &b);
            b.evict(h.key);
        }
        EXPECT_FALSE(b.resident(keys[0]));
        EXPECT_EQ(pool->tilesHeld(), 10u);
        b.fill({keys.data() + 2, 2});  // into the freed slots: no new storage
        EXPECT_EQ(pool->bytesAllocated(), allocated);
        EXPECT_EQ(pool->tilesHeld(), 12u);
    }
    EXPECT_EQ(pool->tilesHeld(), 0u);  // destroyed maps give their tiles back
}

// Slots' storage never overlaps and each block ends in zeroed slack, for tiles small (many
// blocks a storage chunk) and large (a block bigger than a chunk): every slot's bytes
// written with its own pattern read back whole after all are written.
TEST(TilePool, SlotsOwnTheirBytesAcrossBlocksAndChunks) {
    for (const size_t tileBytes : {size_t{3888}, size_t{200000}}) {
        TilePool pool(tileBytes);
        const int slots = tileBytes < 10000 ? 3000 : 100;  // 47 blocks; 2 blocks of 12.8 MB
        std::vector<int> slot(static_cast<size_t>(slots));
        for (int k = 0; k < slots; ++k) {
            slot[static_cast<size_t>(k)] =
                pool.allocate(nullptr, static_cast<uint64_t>(k), false, 0);
            std::memset(pool.data(slot[static_cast<size_t>(k)]), k % 251, tileBytes);
        }
        for (int k = 0; k < slots; ++k) {
            const unsigned char* d = pool.data(slot[static_cast<size_t>(k)]);
            size_t wrong = 0;
            for (size_t b = 0; b < tileBytes; ++b)
                wrong += d[b] != static_cast<unsigned char>(k % 251);
            ASSERT_EQ(wrong, 0u) << "slot " << k << ", tiles of " << tileBytes << " bytes";
        }
        // The slack after each block's last tile.
        for (int k = 63; k < slots; k += 64) {
            const unsigned char* end = pool.data(slot[static_cast<size_t>(k)]) + tileBytes;
            for (size_t b = 0; b < TilePool::kSlackBytes; ++b) ASSERT_EQ(end[b], 0) << k;
        }
    }
}

}  // namespace
}  // namespace mpshade
