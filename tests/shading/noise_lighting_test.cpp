// Noise is deterministic with documented ranges; lighting and occlusion match their
// formulas and simple analytic cases.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "geometry/ray_scene.h"
#include "shading/lighting.h"
#include "shading/lighting_avx2.h"
#include "shading/lower.h"
#include "shading/noise.h"
#include "shading/noise_paths.h"
#include "shading/shader_harness.h"

namespace mpshade {
namespace {

TEST(Noise, ZeroOnTheLatticeAndWithinRange) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> uni(-50.0f, 50.0f);
    for (int i = 0; i < 20000; ++i) {
        const float x = uni(rng), y = uni(rng), z = uni(rng);
        const float n = snoise3(x, y, z);
        ASSERT_GE(n, -1.0f);
        ASSERT_LE(n, 1.0f);
        ASSERT_EQ(snoise3(std::floor(x), std::floor(y), std::floor(z)), 0.0f);
        const float c = cellnoise3(x, y, z);
        ASSERT_GE(c, 0.0f);
        ASSERT_LT(c, 1.0f);
        // Constant over the unit cell.
        ASSERT_EQ(c,
                  cellnoise3(std::floor(x) + 0.01f, std::floor(y) + 0.99f, std::floor(z) + 0.5f));
        ASSERT_FLOAT_EQ(noise3(x, y, z), 0.5f + 0.5f * n);
    }
}

TEST(Noise, IsContinuousAndNotTrivial) {
    float lo = 1, hi = -1;
    for (int i = 0; i < 1000; ++i) {
        const float x = i * 0.0137f;
        const float a = snoise3(x, 0.3f, 0.7f), b = snoise3(x + 1e-4f, 0.3f, 0.7f);
        ASSERT_LT(std::fabs(a - b), 1e-3f);
        lo = std::fmin(lo, a);
        hi = std::fmax(hi, a);
    }
    EXPECT_LT(lo, -0.2f);
    EXPECT_GT(hi, 0.2f);
}

TEST(Noise, GoldenValuesAreStable) {
    // The noise is part of every image's identity: pinned to numbers taken once (noise.cpp
    // at this commit), so a change to the hash, the gradients, the fade curve or the octave
    // sums fails here even though the reference and multi-phase paths would change alike.
    // 1e-6: room for a compiler contracting a*b+c into one rounding, nothing more.
    struct Golden {
        float x, y, z, snoise, fbm5, turbulence5;
    };
    const Golden kGolden[] = {
        {0.5f, 0.25f, 0.125f, 0.546897054f, 0.316306233f, 0.777487874f},
        {-3.3f, 7.1f, 2.2f, -0.0580697805f, 0.0656894296f, 0.259846032f},
        {10.75f, -0.6f, 5.5f, -0.253137738f, -0.442625791f, 0.525121689f},
        {1000.3f, 2.7f, -8.1f, -0.0468311906f, -0.127799749f, 0.176235795f},
    };
    for (const Golden& g : kGolden) {
        EXPECT_NEAR(snoise3(g.x, g.y, g.z), g.snoise, 1e-6f) << g.x;
        EXPECT_NEAR(fbm3(g.x, g.y, g.z, 5), g.fbm5, 1e-6f) << g.x;
        EXPECT_NEAR(turbulence3(g.x, g.y, g.z, 5), g.turbulence5, 1e-6f) << g.x;
        // The octave sums as documented, from snoise3 itself.
        float fbm = 0.0f, turb = 0.0f, f = 1.0f, a = 1.0f;
        for (int o = 0; o < 5; ++o, f *= 2.0f, a *= 0.5f) {
            const float n = snoise3(g.x * f, g.y * f, g.z * f);
            fbm += a * n;
            turb += a * std::fabs(n);
        }
        EXPECT_NEAR(fbm3(g.x, g.y, g.z, 5), fbm, 1e-6f);
        EXPECT_NEAR(turbulence3(g.x, g.y, g.z, 5), turb, 1e-6f);
    }
    EXPECT_NEAR(cellnoise3(1.5f, -2.5f, 3.5f), 0.983730853f, 1e-7f);
    EXPECT_NEAR(cellnoise3(-7.2f, 0.1f, 100.9f), 0.454682291f, 1e-7f);
    // Period 256 on the lattice.
    EXPECT_FLOAT_EQ(snoise3(0.5f, 0.25f, 0.125f), snoise3(0.5f, 0.25f, 0.125f + 256.0f));
}

TEST(Noise, LanesAreTheOnePointValuesBitForBit) {
    // The lane functions compute 8 or 16 points at a time in vector registers; each value
    // must be the one-point function's, bit for bit, at every scale, on lattice points, at
    // tiny negatives (whose fraction rounds), beyond the vector path's range (2^30, left to
    // the one-point function, whose value there is not zero where another coordinate is
    // fractional) and at non-finite inputs, for run lengths that are not multiples of the
    // lane count -- by every build this processor runs, and by the one the public functions
    // choose.
    std::mt19937 rng(23);
    constexpr int kMax = 203;
    std::vector<float> x(kMax), y(kMax), z(kMax), out(kMax);
    auto same = [](float a, float b) { return std::memcmp(&a, &b, sizeof(float)) == 0; };
    std::vector<NoisePath> paths;
    for (NoisePath path : {NoisePath::Portable, NoisePath::Avx2, NoisePath::Avx512Vbmi})
        if (noisePathAvailable(path)) paths.push_back(path);
    for (float scale : {1e-30f, 1.0f, 37.0f, 5e4f, 2e9f, 3e38f}) {
        std::uniform_real_distribution<float> uni(-scale, scale);
        for (int i = 0; i < kMax; ++i) {
            x[i] = uni(rng), y[i] = uni(rng), z[i] = uni(rng);
            if (i % 5 == 0) x[i] = std::floor(x[i]);
            // A huge coordinate beside fractional ones: not on the lattice, not zero.
            if (i % 3 == 1) y[i] = 0.37f * static_cast<float>(i % 17), z[i] = 0.01f * i;
            if (i % 11 == 3) y[i] = -1e-40f;
            if (i % 23 == 7) z[i] = std::numeric_limits<float>::quiet_NaN();
            if (i % 29 == 9) x[i] = -std::numeric_limits<float>::infinity();
        }
        for (int m : {1, 8, 13, 16, 17, 31, kMax}) {
            snoise3Lanes(x.data(), y.data(), z.data(), out.data(), m);
            for (int i = 0; i < m; ++i)
                ASSERT_TRUE(same(out[i], snoise3(x[i], y[i], z[i])))
                    << scale << " lane " << i << ": " << out[i];
            noise3Lanes(x.data(), y.data(), z.data(), out.data(), m);
            for (int i = 0; i < m; ++i)
                ASSERT_TRUE(same(out[i], noise3(x[i], y[i], z[i]))) << scale << " lane " << i;
            fbm3Lanes(x.data(), y.data(), z.data(), 6, out.data(), m);
            for (int i = 0; i < m; ++i)
                ASSERT_TRUE(same(out[i], fbm3(x[i], y[i], z[i], 6))) << scale << " lane " << i;
            turbulence3Lanes(x.data(), y.data(), z.data(), 4, out.data(), m);
            for (int i = 0; i < m; ++i)
                ASSERT_TRUE(same(out[i], turbulence3(x[i], y[i], z[i], 4)))
                    << scale << " lane " << i;
            for (NoisePath path : paths) {
                const int p = static_cast<int>(path);
                noiseLanesOn(path, x.data(), y.data(), z.data(), 1, NoiseSum::Single, out.data(),
                             m);
                for (int i = 0; i < m; ++i)
                    ASSERT_TRUE(same(out[i], snoise3(x[i], y[i], z[i])))
                        << "path " << p << " scale " << scale << " lane " << i;
                noiseLanesOn(path, x.data(), y.data(), z.data(), 7, NoiseSum::Fbm, out.data(), m);
                for (int i = 0; i < m; ++i)
                    ASSERT_TRUE(same(out[i], fbm3(x[i], y[i], z[i], 7)))
                        << "path " << p << " scale " << scale << " lane " << i;
                noiseLanesOn(path, x.data(), y.data(), z.data(), 3, NoiseSum::Turbulence,
                             out.data(), m);
                for (int i = 0; i < m; ++i)
                    ASSERT_TRUE(same(out[i], turbulence3(x[i], y[i], z[i], 3)))
                        << "path " << p << " scale " << scale << " lane " << i;
            }
        }
    }
}

TEST(Noise, EveryLatticeCellHashesAsTheOnePointFunction) {
    // Points in each of the 256^3 cells' residues would take long; instead every cell
    // coordinate 0..255 on each axis in turn (the others swept with it), with fractions
    // that make all eight corners matter, so a lookup wrong for any index (a table half, a
    // carry past 255) changes some value.
    constexpr int kCells = 256 * 3;
    std::vector<float> x(kCells), y(kCells), z(kCells), out(kCells);
    for (int i = 0; i < kCells; ++i) {
        const int c = i % 256, axis = i / 256;
        const float a = static_cast<float>(c) + 0.31f, b = static_cast<float>(255 - c) + 0.77f;
        const float d = static_cast<float>((c * 37) % 256) + 0.53f;
        x[i] = axis == 0 ? a : (axis == 1 ? b : d);
        y[i] = axis == 0 ? b : (axis == 1 ? d : a);
        z[i] = axis == 0 ? d : (axis == 1 ? a : b) - 512.0f;  // negative cells wrap too
    }
    for (NoisePath path : {NoisePath::Avx2, NoisePath::Avx512Vbmi}) {
        if (!noisePathAvailable(path)) continue;
        noiseLanesOn(path, x.data(), y.data(), z.data(), 1, NoiseSum::Single, out.data(), kCells);
        for (int i = 0; i < kCells; ++i)
            ASSERT_EQ(out[i], snoise3(x[i], y[i], z[i]))
                << "path " << static_cast<int>(path) << " cell " << i;
    }
}

TEST(Noise, NonFiniteAndHugeInputsAreSafe) {
    EXPECT_EQ(snoise3(NAN, 0, 0), 0.0f);
    EXPECT_EQ(snoise3(INFINITY, 0, 0), 0.0f);
    EXPECT_TRUE(std::isfinite(snoise3(3e38f, -3e38f, 1e20f)));
    EXPECT_EQ(cellnoise3(NAN, 1, 1), 0.0f);
    EXPECT_TRUE(std::isfinite(cellnoise3(3e38f, -3e38f, 1e20f)));
}

TEST(Lighting, DiffuseSpecularAndPhongFormulas) {
    LightSample distant;
    distant.kind = LightKind::Distant;
    distant.color = glm::vec3(2, 1, 0.5f);
    distant.toLight = glm::normalize(glm::vec3(0, 1, 1));
    const glm::vec3 N(0, 1, 0), V = glm::normalize(glm::vec3(0, 1, -1)), P(0);
    const float ndl = glm::dot(N, distant.toLight);
    EXPECT_NEAR(shadeLightOne(Op::Diffuse, distant, P, N, V, 0).x, 2.0f * ndl, 1e-6f);
    // V is the mirror of L: H = N, so D = 1 / (pi alpha^2).
    const float r = 0.5f, alpha = r * r;
    const float D = 1.0f / (3.14159265f * alpha * alpha);
    EXPECT_NEAR(shadeLightOne(Op::Specular, distant, P, N, V, r).y, 1.0f * D * ndl / 4.0f, 1e-4f);
    // Phong: R = reflect(-V, N) = L exactly, so the lobe is at its peak.
    EXPECT_NEAR(shadeLightOne(Op::Phong, distant, P, N, V, 20.0f).z, 0.5f, 1e-5f);
    // Lit from behind: nothing.
    EXPECT_EQ(shadeLightOne(Op::Diffuse, distant, P, -N, V, 0), glm::vec3(0.0f));

    LightSample point;
    point.kind = LightKind::Point;
    point.color = glm::vec3(8.0f);
    point.position = glm::vec3(0, 2, 0);
    EXPECT_NEAR(shadeLightOne(Op::Diffuse, point, P, N, V, 0).x, 8.0f / 4.0f, 1e-6f);
    // At the light's position: no NaN.
    EXPECT_EQ(shadeLightOne(Op::Diffuse, point, point.position, N, V, 0), glm::vec3(0.0f));
}

TEST(Lighting, ShaderSumsLightsAndFoldsFixedAmbient) {
    ShaderBinding binding;
    binding.lights.resize(3);
    binding.lights[0].kind = LightKind::Ambient;
    binding.lights[0].color[0] = binding.lights[0].color[1] = binding.lights[0].color[2] = 0.25f;
    binding.lights[1].kind = LightKind::Distant;
    binding.lights[2].kind = LightKind::Distant;
    std::vector<LightSample> lights(3);
    lights[1].kind = lights[2].kind = LightKind::Distant;
    lights[1].color = glm::vec3(1.0f);
    lights[1].toLight = glm::vec3(0, 1, 0);
    lights[2].color = glm::vec3(0.5f);
    lights[2].toLight = glm::normalize(glm::vec3(1, 1, 0));
    ShadingUniforms uniforms;
    uniforms.lights = lights;
    test::ShadingPoint p;
    const auto r =
        test::runShader("surface l() { Ci = ambient() + diffuse(N); }", {p}, binding, uniforms);
    EXPECT_NEAR(r.Ci[0].x, 0.25f + 1.0f + 0.5f * std::sqrt(0.5f), 1e-6f);
}

TEST(Occlusion, OpenOutsideClosedInside) {
    const Surface sphere = Sphere{1.0f};
    const SurfaceRayScene rays(sphere);
    ShadingUniforms uniforms;
    uniforms.occluder = &rays;
    uniforms.occlusionBias = 1e-4f;
    test::ShadingPoint outside, inside;
    outside.P = glm::vec3(0, 1, 0);
    outside.N = glm::vec3(0, 1, 0);
    inside.P = glm::vec3(0, 0, 0);
    inside.N = glm::vec3(0, 1, 0);
    const auto r = test::runShader("surface o() { Ci = color(occlusion(P, N, 64)); }",
                                   {outside, inside}, {}, uniforms);
    EXPECT_EQ(r.Ci[0].x, 1.0f);
    EXPECT_EQ(r.Ci[1].x, 0.0f);
    EXPECT_EQ(r.counters.occlusionRays, 128u);
}

TEST(Occlusion, StratifiedDirectionsCountExactlyUnderASphere) {
    // Below a unit sphere at distance D along N, a cosine-weighted direction with
    // sin^2(angle to N) = u1 hits it exactly when u1 < 1 / D^2. Ray i has
    // u1 = (i + 1/2) / 64, so with 1 / D^2 = 0.2547 (64 x 0.2547 = 16.3) rays 0..15 hit:
    // open 48 / 64 exactly. (Strata at i / 64 would hit 17; every ray is at least 0.3
    // degrees from the sphere's silhouette, far beyond its tessellation's 0.015.)
    const Surface sphere = Sphere{1.0f};
    const SurfaceRayScene rays(sphere);
    const float D = 1.0f / std::sqrt(0.2547f);
    const float P[3] = {0.0f, -D, 0.0f}, N[3] = {0.0f, 1.0f, 0.0f};
    const float* args[6] = {&P[0], &P[1], &P[2], &N[0], &N[1], &N[2]};
    float open = -1.0f;
    EXPECT_EQ(occlusionLanes(&rays, 0.0f, 64, args, &open, 1), 64u);
    EXPECT_EQ(open, 48.0f / 64.0f);
}

TEST(Occlusion, EveryLaneOfALongRunCountsItsOwnRays) {
    // 150 lanes (rays go to Embree in sets of up to 64 lanes) below the unit sphere at four
    // distances, with 1 / D^2 = (j + 0.3) / 64: rays 0..j-1 hit, open (64 - j) / 64 exactly
    // (as in StratifiedDirectionsCountExactlyUnderASphere), and every seventh lane without
    // a usable normal or point: open 1, no rays traced.
    const Surface sphere = Sphere{1.0f};
    const SurfaceRayScene rays(sphere);
    constexpr int m = 150;
    const int hits[4] = {4, 10, 16, 22};
    std::vector<float> in(6 * m, 0.0f);
    std::vector<float> expected(m);
    int usable = 0;
    for (int l = 0; l < m; ++l) {
        const int j = hits[(l * 3 + l / 5) % 4];
        in[1 * m + l] = -1.0f / std::sqrt((static_cast<float>(j) + 0.3f) / 64.0f);
        in[4 * m + l] = 1.0f;
        expected[l] = static_cast<float>(64 - j) / 64.0f;
        if (l % 7 == 3) {
            if (l % 2)
                in[4 * m + l] = 0.0f;  // zero normal
            else
                in[0 * m + l] = std::numeric_limits<float>::quiet_NaN();
            expected[l] = 1.0f;
        } else {
            ++usable;
        }
    }
    const float* args[6];
    for (int k = 0; k < 6; ++k) args[k] = &in[static_cast<size_t>(k) * m];
    std::vector<float> open(m, -1.0f);
    EXPECT_EQ(occlusionLanes(&rays, 0.0f, 64, args, open.data(), m), 64u * usable);
    for (int l = 0; l < m; ++l) EXPECT_EQ(open[l], expected[l]) << "lane " << l;
    // Told to stop, or past a deadline, before it starts: no ray traced at all. Not told,
    // a deadline far off: every ray, the same counts.
    StopSignal told;
    told.request();
    EXPECT_EQ(occlusionLanes(&rays, 0.0f, 64, args, open.data(), m, &told), 0u);
    const StopSignal late(StopSignal::Clock::now() - std::chrono::milliseconds(1));
    EXPECT_EQ(occlusionLanes(&rays, 0.0f, 64, args, open.data(), m, &late), 0u);
    const StopSignal later(StopSignal::Clock::now() + std::chrono::hours(1));
    EXPECT_EQ(occlusionLanes(&rays, 0.0f, 64, args, open.data(), m, &later), 64u * usable);
    for (int l = 0; l < m; ++l) EXPECT_EQ(open[l], expected[l]) << "lane " << l;
}

// A point light above and to the side, and a distant one: the lights the lane tests shade.
std::pair<LightSample, LightSample> pointAndDistantLights() {
    LightSample point, distant;
    point.kind = LightKind::Point;
    point.position = glm::vec3(0.3f, 2.0f, -0.5f);
    point.color = glm::vec3(3.0f, 2.0f, 1.0f);
    distant.kind = LightKind::Distant;
    distant.toLight = glm::normalize(glm::vec3(0.2f, 1.0f, 0.4f));
    distant.color = glm::vec3(0.5f, 1.0f, 1.5f);
    return {point, distant};
}

TEST(Lighting, EveryLaneOfARunMatchesTheOneLaneFormula) {
    // shadeLight takes four lanes at a time in vector registers and the rest one at a time;
    // each lane must be the one-lane formula's value, at edge inputs too: a point at the
    // light, a normal facing away, roughness NaN, 0 and above 1, a zero normal.
    std::mt19937 rng(17);
    std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
    constexpr int m = 23;  // five runs of four and three single lanes
    const auto [point, distant] = pointAndDistantLights();
    std::vector<float> in(10 * m), out(3 * m);
    for (int l = 0; l < m; ++l) {
        const glm::vec3 N = glm::normalize(glm::vec3(uni(rng), 1.0f, uni(rng)));
        const glm::vec3 V = glm::normalize(glm::vec3(uni(rng), 1.0f + uni(rng), uni(rng)));
        const glm::vec3 P(uni(rng), uni(rng), uni(rng));
        for (int k = 0; k < 3; ++k) {
            in[k * m + l] = P[k];
            in[(3 + k) * m + l] = N[k];
            in[(6 + k) * m + l] = V[k];
        }
        in[9 * m + l] = 0.05f + 0.9f * (0.5f + 0.5f * uni(rng));
    }
    for (int k = 0; k < 3; ++k) in[k * m + 2] = point.position[k];           // at the light
    for (int k = 0; k < 3; ++k) in[(3 + k) * m + 5] = -in[(3 + k) * m + 5];  // facing away
    for (int k = 0; k < 3; ++k) in[(3 + k) * m + 21] = 0.0f;  // zero normal, in the tail
    in[9 * m + 1] = std::nanf("");
    in[9 * m + 6] = 0.0f;
    in[9 * m + 9] = 3.0f;
    const float* args[10];
    for (int k = 0; k < 10; ++k) args[k] = &in[static_cast<size_t>(k) * m];
    float* rgb[3] = {&out[0], &out[m], &out[2 * m]};
    for (const LightSample& light : {point, distant})
        for (Op op : {Op::Diffuse, Op::Specular}) {
            shadeLight(op, light, args, rgb, m);
            for (int l = 0; l < m; ++l) {
                const auto at = [&](int row) {
                    return glm::vec3(in[row * m + l], in[(row + 1) * m + l], in[(row + 2) * m + l]);
                };
                const glm::vec3 want = shadeLightOne(op, light, at(0), at(3), at(6), in[9 * m + l]);
                for (int k = 0; k < 3; ++k) {
                    ASSERT_TRUE(std::isfinite(out[k * m + l])) << "lane " << l;
                    ASSERT_NEAR(out[k * m + l], want[k], 1e-5f * (1.0f + std::fabs(want[k])))
                        << "lane " << l << " channel " << k << " op " << static_cast<int>(op)
                        << (light.kind == LightKind::Point ? " point" : " distant");
                }
            }
        }
}

TEST(Lighting, EightLanesInAvx2AreTheBaselineBitForBit) {
    // 37 lanes: four runs of eight, one of four and one single lane, with the edge inputs
    // of the test above spread over the runs and the tails, and a normal of huge length.
    if (!shadeLightAvx2Available()) GTEST_SKIP() << "no AVX2 on this processor";
    std::mt19937 rng(29);
    std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
    constexpr int m = 37;
    const auto [point, distant] = pointAndDistantLights();
    std::vector<float> in(10 * m);
    for (float& x : in) x = uni(rng);
    for (int l = 0; l < m; ++l) in[9 * m + l] = 0.5f + 0.5f * uni(rng);
    for (int k = 0; k < 3; ++k) in[k * m + 3] = point.position[k];  // at the light
    for (int k = 0; k < 3; ++k) in[(3 + k) * m + 17] = 0.0f;        // zero normal
    for (int k = 0; k < 3; ++k) in[(3 + k) * m + 34] *= 1e18f;      // huge, in the tail
    in[9 * m + 9] = std::nanf("");
    in[9 * m + 33] = 0.0f;
    in[9 * m + 36] = 3.0f;
    const float* args[10];
    for (int k = 0; k < 10; ++k) args[k] = &in[static_cast<size_t>(k) * m];
    for (const LightSample& light : {point, distant})
        for (Op op : {Op::Diffuse, Op::Specular}) {
            std::vector<float> wide(3 * m, -1.0f), base(3 * m, -2.0f);
            float* w[3] = {&wide[0], &wide[m], &wide[2 * m]};
            float* b[3] = {&base[0], &base[m], &base[2 * m]};
            shadeLightAvx2(op, light, args, w, m);
            shadeLightBaseline(op, light, args, b, m);
            for (int i = 0; i < 3 * m; ++i)
                ASSERT_EQ(std::memcmp(&wide[i], &base[i], sizeof(float)), 0)
                    << "lane " << i % m << " channel " << i / m << " op " << static_cast<int>(op)
                    << " " << wide[i] << " against " << base[i];
        }
}

TEST(Lighting, ANegatedViewIsTheNegatedArgumentsBitForBit) {
    // specular(N, -I, r) reads I and subtracts it (negatedView) instead of a pass negating
    // it first: the same bits in the baseline and AVX2 paths, edge inputs included (a zero
    // and a -0 view component, a point at the light, a zero normal).
    std::mt19937 rng(41);
    std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
    constexpr int m = 37;
    const auto [point, distant] = pointAndDistantLights();
    std::vector<float> in(10 * m), negated(3 * m);
    for (float& x : in) x = uni(rng);
    for (int l = 0; l < m; ++l) in[9 * m + l] = 0.5f + 0.5f * uni(rng);
    for (int k = 0; k < 3; ++k) in[k * m + 3] = point.position[k];
    for (int k = 0; k < 3; ++k) in[(3 + k) * m + 17] = 0.0f;
    in[6 * m + 5] = 0.0f, in[7 * m + 5] = -0.0f, in[8 * m + 36] = -0.0f;
    for (int i = 0; i < 3 * m; ++i) negated[i] = -in[6 * m + i];
    const float* args[10];
    for (int k = 0; k < 10; ++k) args[k] = &in[static_cast<size_t>(k) * m];
    const float* negatedArgs[10];
    std::copy(args, args + 10, negatedArgs);
    for (int k = 0; k < 3; ++k) negatedArgs[6 + k] = &negated[static_cast<size_t>(k) * m];
    for (const bool baseline : {true, false})
        for (const LightSample& light : {point, distant}) {
            std::vector<float> want(3 * m, -1.0f), got(3 * m, -2.0f);
            float* w[3] = {&want[0], &want[m], &want[2 * m]};
            float* g[3] = {&got[0], &got[m], &got[2 * m]};
            if (baseline) {
                shadeLightBaseline(Op::Specular, light, args, w, m);
                shadeLightBaseline(Op::Specular, light, negatedArgs, g, m, true);
            } else {
                shadeLight(Op::Specular, light, args, w, m);
                shadeLight(Op::Specular, light, negatedArgs, g, m, true);
            }
            for (int i = 0; i < 3 * m; ++i)
                ASSERT_EQ(std::memcmp(&want[i], &got[i], sizeof(float)), 0)
                    << "lane " << i % m << " channel " << i / m << (baseline ? " baseline" : "")
                    << " " << got[i] << " against " << want[i];
        }
}

TEST(Lighting, ASpecularReadsItsNegatedViewWithoutANegationPass) {
    // specular(N, -I, r): the three negations are not run (passCount), and the result is the
    // bits of the same shader whose -I is also an output (its negations then kept and read).
    ShaderBinding binding;
    binding.lights.resize(2);
    binding.lights[0].kind = LightKind::Point;
    binding.lights[1].kind = LightKind::Distant;
    const auto [point, distant] = pointAndDistantLights();
    ShadingUniforms uniforms;
    const std::vector<LightSample> lights = {point, distant};
    uniforms.lights = lights;
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
    std::vector<test::ShadingPoint> points(21);
    for (test::ShadingPoint& p : points) {
        p.P = glm::vec3(uni(rng), uni(rng), uni(rng));
        p.N = glm::normalize(glm::vec3(uni(rng), 1.0f, uni(rng)));
        p.I = glm::normalize(glm::vec3(uni(rng), -1.0f, uni(rng)));
    }
    points[4].I.x = -0.0f;
    const std::string fused = "surface f() { Ci = specular(N, -I, 0.3); }";
    const std::string kept =
        "surface k() { vector V = -I; Ci = specular(N, V, 0.3); Oi = color(V); }";
    const ShaderKernel kernel(lowerShader(*compileShaderText("f.sl", fused), binding));
    // The negations' three passes, and the second light's sum with the first written in its
    // own pass (LightEpilogue).
    EXPECT_EQ(kernel.passCount() + 6, kernel.instructionCount());
    const auto a = test::runKernel(kernel, points, uniforms);
    const auto b = test::runShader(kept, points, binding, uniforms);
    for (size_t i = 0; i < points.size(); ++i)
        for (int k = 0; k < 3; ++k)
            ASSERT_EQ(std::memcmp(&a.Ci[i][k], &b.Ci[i][k], sizeof(float)), 0)
                << "point " << i << " channel " << k;
}

TEST(Lighting, ALightEndingInSumsWritesThemInItsOwnPass) {
    // Ci = base + 0.5 specular and Oi = t + diffuse: each light's sums (and the product
    // fused into Ci's) written by the light, each product and sum rounded alone, against
    // the lane light with no epilogue and the arithmetic done here.
    ShaderBinding binding;
    binding.lights.resize(1);
    binding.lights[0].kind = LightKind::Point;
    const auto [point, distant] = pointAndDistantLights();
    (void)distant;
    ShadingUniforms uniforms;
    const std::vector<LightSample> lights = {point};
    uniforms.lights = lights;
    std::mt19937 rng(9);
    std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
    std::vector<test::ShadingPoint> points(21);  // eight lanes twice, four, one
    for (test::ShadingPoint& p : points) {
        p.P = glm::vec3(uni(rng), uni(rng), uni(rng));
        p.N = glm::normalize(glm::vec3(uni(rng), 1.0f, uni(rng)));
        p.I = glm::normalize(glm::vec3(uni(rng), -1.0f, uni(rng)));
        p.u = uni(rng), p.v = uni(rng), p.s = 1e-3f * uni(rng), p.t = uni(rng);
    }
    const std::string source =
        "surface e() { Ci = color(u, v, s) + 0.5 * specular(N, -I, 0.3);\n"
        "  Oi = color(t) + diffuse(N); }";
    const ShaderKernel kernel(lowerShader(*compileShaderText("e.sl", source), binding));
    // Two light passes and nothing else but reading the inputs: the three fused products'
    // sums and the three plain sums are no passes of their own, nor are the negations.
    EXPECT_EQ(kernel.instructionCount() - kernel.passCount(), 3u + 3u + 3u + 3u);
    const auto r = test::runKernel(kernel, points, uniforms);
    const size_t n = points.size();
    std::vector<float> rows[10], spec[3], diff[3];
    for (auto& row : rows) row.resize(n);
    for (int c = 0; c < 3; ++c) spec[c].resize(n), diff[c].resize(n);
    for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) {
            rows[c][i] = points[i].P[c];
            rows[3 + c][i] = points[i].N[c];
            rows[6 + c][i] = -points[i].I[c];
            rows[9][i] = 0.3f;
        }
    const float* args[10];
    for (int k = 0; k < 10; ++k) args[k] = rows[k].data();
    float* specRows[3] = {spec[0].data(), spec[1].data(), spec[2].data()};
    float* diffRows[3] = {diff[0].data(), diff[1].data(), diff[2].data()};
    shadeLightBaseline(Op::Specular, point, args, specRows, static_cast<int>(n));
    shadeLightBaseline(Op::Diffuse, point, args, diffRows, static_cast<int>(n));
    for (size_t i = 0; i < n; ++i) {
        const float base[3] = {points[i].u, points[i].v, points[i].s};
        for (int c = 0; c < 3; ++c) {
            const volatile float product = 0.5f * spec[c][i];  // rounded alone
            EXPECT_EQ(r.Ci[i][c], base[c] + product) << "point " << i << " channel " << c;
            EXPECT_EQ(r.Oi[i][c], points[i].t + diff[c][i]) << "point " << i << " channel " << c;
        }
    }
}

TEST(Lighting, GgxRoughnessIsFlooredAtAHundredth) {
    // docs/shading-language.md: roughness is clamped to [0.01, 1]. At the mirror
    // direction (H = N) D = 1 / (pi alpha^2), alpha = r^2: a roughness of 0.001 must give
    // the value of 0.01, and 2 that of 1.
    LightSample distant;
    distant.kind = LightKind::Distant;
    distant.color = glm::vec3(1.0f);
    distant.toLight = glm::normalize(glm::vec3(0, 1, 1));
    const glm::vec3 N(0, 1, 0), V = glm::normalize(glm::vec3(0, 1, -1)), P(0);
    const float ndl = glm::dot(N, distant.toLight);
    const auto peak = [&](float r) {
        const double alpha = double(r) * r;
        return 1.0 / (3.14159265358979 * alpha * alpha) * ndl / 4.0;
    };
    EXPECT_NEAR(shadeLightOne(Op::Specular, distant, P, N, V, 0.001f).x, peak(0.01f),
                1e-3 * peak(0.01f));
    EXPECT_NEAR(shadeLightOne(Op::Specular, distant, P, N, V, 2.0f).x, peak(1.0f),
                1e-3 * peak(1.0f));
    // The batched path the renderers run, through a shader: the viewer at the mirror
    // direction (I = -V), roughness below the floor. This was infinite (1 - ndh^2 (1 - a2)
    // cancelled to 0 in float).
    ShaderBinding binding;
    binding.lights.resize(1);
    binding.lights[0].kind = LightKind::Distant;
    std::vector<LightSample> lights = {distant};
    ShadingUniforms uniforms;
    uniforms.lights = lights;
    test::ShadingPoint p;
    p.N = p.Ng = N;
    p.I = -V;
    const auto r =
        test::runShader("surface g() { Ci = specular(N, -I, 0.001); }", {p}, binding, uniforms);
    EXPECT_NEAR(r.Ci[0].x, peak(0.01f), 1e-3 * peak(0.01f));
}

TEST(Occlusion, HalfOpenBesideAWall) {
    // A point on a large plane, with N along the plane: the plane blocks half the
    // hemisphere, which for cosine weighting is exactly half.
    const Surface plane = Plane{1000.0f, 1000.0f};
    const SurfaceRayScene rays(plane);
    ShadingUniforms uniforms;
    uniforms.occluder = &rays;
    test::ShadingPoint p;
    p.P = glm::vec3(0, 0.001f, 0);
    p.N = glm::vec3(1, 0, 0);
    const auto r =
        test::runShader("surface o() { Ci = color(occlusion(P, N, 256)); }", {p}, {}, uniforms);
    EXPECT_NEAR(r.Ci[0].x, 0.5f, 0.03f);
}

}  // namespace
}  // namespace mpshade
