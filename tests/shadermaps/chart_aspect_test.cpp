// Shader maps whose charts are stretched (chart_aspect.h): the shift each chart gets against
// numbers worked out by hand, texels at their own chart points, probes still exact on linear
// functions, and a footprint round on the surface read by a single tap.
#include <cmath>
#include <memory>
#include <random>

#include <gtest/gtest.h>

#include "shadermaps/chart_aspect.h"
#include "shadermaps/probe.h"
#include "shadermaps/shader_map.h"
#include "shading/factoring.h"
#include "shading/shader_compiler.h"

namespace mpshade {
namespace {

struct Shift {
    int u, v;
};

Shift shiftOf(const Surface& surface, int maxShift = kMaxChartShift) {
    const ChartShifts s = chartShifts(surface, maxShift);
    EXPECT_EQ(s.u.size(), 1u);
    return {s.u[0], s.v[0]};
}

TEST(ChartAspect, ShiftsFollowTheParameterizationsStretch) {
    // A plane's u spans its width, v its depth: log2(width / depth), rounded down.
    EXPECT_EQ(shiftOf(Plane{4.0f, 4.0f}).u + shiftOf(Plane{4.0f, 4.0f}).v, 0);
    EXPECT_EQ(shiftOf(Plane{4.0f, 1.0f}).v, 2);
    EXPECT_EQ(shiftOf(Plane{4.0f, 1.0f}).u, 0);
    EXPECT_EQ(shiftOf(Plane{1.0f, 4.0f}).u, 2);
    EXPECT_EQ(shiftOf(Plane{1.0f, 4.0f}).v, 0);
    // Either side of 2 and of 4.
    EXPECT_EQ(shiftOf(Plane{1.9f, 1.0f}).v, 0);
    EXPECT_EQ(shiftOf(Plane{2.1f, 1.0f}).v, 1);
    EXPECT_EQ(shiftOf(Plane{3.9f, 1.0f}).v, 1);
    EXPECT_EQ(shiftOf(Plane{4.1f, 1.0f}).v, 2);
    // 64:1 is capped: at kMaxChartShift, or what the map's resolution leaves room for.
    EXPECT_EQ(shiftOf(Plane{64.0f, 1.0f}).v, kMaxChartShift);
    EXPECT_EQ(shiftOf(Plane{64.0f, 1.0f}, 1).v, 1);
    EXPECT_EQ(shiftOf(Plane{64.0f, 1.0f}, 0).v, 0);
    // A torus: |dP/du| = 2 pi (R + r cos 2 pi v), |dP/dv| = 2 pi r, the area their product.
    // Over the 4 x 4 grid's rows cos = +-0.7071: R 1, r 0.25 weighs log2 4.707 = 2.235 by
    // 1.177 and log2 3.293 = 1.719 by 0.823, mean 2.02; r 0.5 gives 1.437 by 1.354 and 0.371
    // by 0.646, mean 1.09; a sphere's rows (sin of latitude 0.383 and 0.924 weigh log2 of
    // twice that) 0.51.
    EXPECT_EQ(shiftOf(Torus{1.0f, 0.25f}).v, 2);
    EXPECT_EQ(shiftOf(Torus{1.0f, 0.5f}).v, 1);
    EXPECT_EQ(shiftOf(Torus{1.0f, 0.5f}).u, 0);
    EXPECT_EQ(shiftOf(Sphere{1.0f}).v, 0);
    EXPECT_EQ(shiftOf(Sphere{1.0f}).u, 0);
}

TEST(ChartAspect, ManyChartsKeepSquareGrids) {
    PointCloud cloud;
    for (int i = 0; i <= kMaxAspectCharts; ++i) {
        cloud.centers.emplace_back(static_cast<float>(i), 0.0f, 0.0f);
        cloud.normals.emplace_back(0.0f, 1.0f, 0.0f);
        cloud.radii.push_back(0.1f);
    }
    const ChartShifts s = chartShifts(cloud);
    ASSERT_EQ(s.u.size(), cloud.centers.size());
    for (size_t c = 0; c < s.u.size(); ++c) ASSERT_EQ(s.u[c] + s.v[c], 0) << c;
    // One disc less and they are measured: a disc's u runs out from its centre, so a polar
    // chart's rings are longer than its spokes (the area-weighted mean of log2(1 / 2 pi u),
    // -1.9 over the grid).
    cloud.centers.pop_back(), cloud.normals.pop_back(), cloud.radii.pop_back();
    EXPECT_EQ(chartShifts(cloud).u[0], 1);
}

TEST(ChartAspect, CoarseLevelTilesCountEachAxis) {
    // 1024 texels a side in tiles of 16, the six coarsest levels (32 .. 1 texels a side):
    // 4 + 1 + 1 + 1 + 1 + 1 = 9 square; shifted by 1 the 32-texel level is 32 x 16, 2 tiles.
    ChartShifts s;
    s.u = {0, 0, 3};
    s.v = {0, 1, 0};
    EXPECT_DOUBLE_EQ(coarseLevelTiles(s, 1024, 16, 6), 9.0 + 7.0 + 7.0);
}

// A map over a 4 x 1 plane of a shader whose static part is linear in u and v.
struct StretchedMap {
    Surface surface = Plane{4.0f, 1.0f};
    FactoredShader factored;
    std::unique_ptr<ShaderKernel> kernel;
    std::unique_ptr<ShaderMap> map;

    explicit StretchedMap(bool aspect) {
        auto ast = compileShaderText(
            "l.sl",
            "surface l() { Ci = color(bake(3 * u + 2 * v + 1), bake(u - v), bake(0.5 * v)) * "
            "(1 + time); }");
        FactorOptions store;
        store.storeAboveCost = 0;
        factored = factorShader(*ast, {}, store);
        kernel = std::make_unique<ShaderKernel>(factored.staticPart);
        ShaderMapOptions options;
        options.resolution = 128;
        options.chartAspect = aspect;
        map = std::make_unique<ShaderMap>(surface, *kernel, ShadingUniforms{}, options);
        map->fillLevels(0, map->levels() - 1);
    }
};

TEST(ChartAspect, AStretchedChartsTexelsLieAtTheirOwnChartPoints) {
    const StretchedMap m(true);
    const ShaderMap& map = *m.map;
    // v a quarter of u's texels, down to one; the tiles as many as the texels need.
    EXPECT_EQ(map.resolutionU(0, 0), 128);
    EXPECT_EQ(map.resolutionV(0, 0), 32);
    EXPECT_EQ(map.tilesU(0, 0), 8);
    EXPECT_EQ(map.tilesV(0, 0), 2);
    EXPECT_EQ(map.resolutionV(0, 5), 1);
    EXPECT_EQ(map.resolutionV(0, 7), 1);
    EXPECT_EQ(map.resolutionU(0, 5), 4);
    for (int level = 0; level < map.levels(); ++level) {
        const int ru = map.resolutionU(0, level), rv = map.resolutionV(0, level);
        for (int j = 0; j < rv; j += 3)
            for (int i = 0; i < ru; i += 5) {
                const float u = (i + 0.5f) / ru, v = (j + 0.5f) / rv;
                const TileKey key = map.tileOf(0, level, i, j);
                ASSERT_GE(map.slotOf(key), 0);
                float t[3];
                map.texel(key, map.slotOf(key), i, j, t);
                ASSERT_NEAR(t[0], 3 * u + 2 * v + 1, 1e-5f) << level << ": " << i << "," << j;
                ASSERT_NEAR(t[1], u - v, 1e-5f);
                ASSERT_NEAR(t[2], 0.5f * v, 1e-5f);
            }
    }
}

TEST(ChartAspect, ProbesOfAStretchedChartAreExactOnLinearFunctions) {
    const StretchedMap m(true);
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> pos(0.3f, 0.7f), size(0.0f, 3.0f), turn(0.0f, 3.1f);
    for (ProbeFilter filter : {ProbeFilter::Trilinear, ProbeFilter::Feline, ProbeFilter::EWA}) {
        ProbeOptions probe;
        probe.filter = filter;
        std::vector<ProbeQuery> qs;
        for (int k = 0; k < 500; ++k) {
            // Footprints round on the surface (a quarter of the chart units along u), turned.
            const float f = std::exp2(size(rng)) / 128.0f, a = turn(rng);
            const float c = std::cos(a), s = std::sin(a);
            qs.push_back({0, pos(rng), pos(rng), 0.25f * f * c, f * s, -0.25f * f * s, f * c});
        }
        std::vector<float> out(3 * qs.size());
        probeShaderMap(*m.map, probe, qs, out.data());
        // Bilinear taps, trilinear levels and Feline's line are symmetric about the point:
        // a linear function's mean is its value there. EWA weighs the texel centres inside
        // its ellipse, not symmetric about the point: off by up to about a texel's worth of
        // the gradient (3 a chart unit; a level-0 texel along u is 1/128), with or without
        // the aspect (0.0093 and 0.0095 over these queries).
        const bool ewa = filter == ProbeFilter::EWA;
        for (size_t k = 0; k < qs.size(); ++k) {
            const float u = qs[k].u, v = qs[k].v;
            ASSERT_NEAR(out[3 * k], 3 * u + 2 * v + 1, ewa ? 0.015f : 8e-6f)
                << static_cast<int>(filter) << " " << k;
            ASSERT_NEAR(out[3 * k + 1], u - v, ewa ? 0.006f : 4e-6f);
            ASSERT_NEAR(out[3 * k + 2], 0.5f * v, ewa ? 0.003f : 2e-6f);
        }
    }
}

TEST(ChartAspect, AFootprintRoundOnTheSurfaceIsOneTap) {
    // On the 4 x 1 plane a footprint round on the surface spans a quarter of the chart
    // units along u that it does along v: 1 level-0 texel each way with the aspect (level 0
    // exactly: one level, one tap), 1 by 4 without (a line of taps).
    for (bool aspect : {true, false}) {
        const StretchedMap m(aspect);
        ProbeOptions probe;
        probe.filter = ProbeFilter::Feline;
        std::vector<ProbeQuery> qs;
        const float f = 1.0f / 32.0f;
        for (int k = 0; k < 64; ++k)
            qs.push_back({0, 0.3f + 0.005f * k, 0.4f + 0.003f * k, 0.25f * f, 0.0f, 0.0f, f});
        std::vector<float> out(3 * qs.size());
        std::vector<TileKey> missing(16);
        ProbeResidency residency{missing.data(), missing.size()};
        probeShaderMap(*m.map, probe, qs, out.data(), &residency);
        if (aspect)
            EXPECT_EQ(residency.bilinearProbes, qs.size());
        else
            EXPECT_GE(residency.bilinearProbes, 4 * qs.size());
    }
}

}  // namespace
}  // namespace mpshade
