// Properties every surface type must have: unit normals that agree with the derivatives,
// derivatives that match finite differences, charts that do not overlap, and ray hits
// whose (chart, u, v) evaluates back to the hit point.
#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <thread>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "geometry/ray_scene.h"
#include "geometry/surface.h"
#include "test_support.h"

namespace mpshade {
namespace {

using test::sourcePath;

struct NamedSurface {
    std::string name;
    std::shared_ptr<const Surface> surface;
    bool hasVertexNormals = false;
};

std::vector<NamedSurface> allSurfaces() {
    std::vector<NamedSurface> s;
    s.push_back({"sphere", std::make_shared<const Surface>(Sphere{1.5f})});
    s.push_back({"torus", std::make_shared<const Surface>(Torus{1.0f, 0.3f})});
    s.push_back({"plane", std::make_shared<const Surface>(Plane{4.0f, 2.0f})});
    s.push_back({"teapot", std::make_shared<const Surface>(
                               loadBezierPatches(sourcePath("examples/teapot/teapot.patches")))});
    s.push_back({"vase_catmark", std::make_shared<const Surface>(SubdivSurface(
                                     loadObjCage(sourcePath("examples/vase/meshes/vase.obj")),
                                     SubdivScheme::Catmark, "vase"))});
    s.push_back({"octahedron_loop", std::make_shared<const Surface>(SubdivSurface(
                                        loadObjCage(sourcePath("tests/data/meshes/octahedron.obj")),
                                        SubdivScheme::Loop, "octa"))});
    s.push_back({"cube_mesh", std::make_shared<const Surface>(PolygonMesh(
                                  readObjPolygons(sourcePath("tests/data/meshes/cube.obj"))))});
    s.push_back({"pentagon_mesh",
                 std::make_shared<const Surface>(
                     PolygonMesh(readObjPolygons(sourcePath("tests/data/meshes/pentagon.obj")))),
                 true});
    s.push_back({"points", std::make_shared<const Surface>(
                               loadPointCloud(sourcePath("tests/data/meshes/points.txt")))});
    return s;
}

class SurfaceProperties : public ::testing::TestWithParam<int> {
  protected:
    static const std::vector<NamedSurface>& surfaces() {
        static const std::vector<NamedSurface> s = allSurfaces();
        return s;
    }
    const NamedSurface& named() const { return surfaces()[static_cast<size_t>(GetParam())]; }
    const Surface& surface() const { return *named().surface; }
};

TEST_P(SurfaceProperties, NormalsAreUnitAndAgreeWithDerivatives) {
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> uni(0.0f, 1.0f);
    const int charts = chartCount(surface());
    ASSERT_GT(charts, 0);
    int oriented = 0, checked = 0;
    for (int i = 0; i < 2000; ++i) {
        const ChartPoint at{static_cast<int>(rng() % static_cast<unsigned>(charts)), uni(rng),
                            uni(rng)};
        const SurfaceSample s = evaluate(surface(), at);
        ASSERT_NEAR(glm::length(s.N), 1.0f, 1e-4f) << named().name;
        ASSERT_NEAR(glm::length(s.Ng), 1.0f, 1e-4f) << named().name;
        ASSERT_GE(glm::dot(s.N, s.Ng), 0.0f) << named().name;
        const glm::vec3 c = glm::cross(s.dPdu, s.dPdv);
        if (glm::length(c) > 1e-4f * glm::length(s.dPdu) * glm::length(s.dPdv) &&
            !named().hasVertexNormals) {
            ++checked;
            if (glm::dot(c, s.Ng) > 0.0f) ++oriented;
        }
    }
    EXPECT_EQ(oriented, checked) << named().name << ": Ng must follow cross(dPdu, dPdv)";
}

TEST_P(SurfaceProperties, DerivativesMatchFiniteDifferences) {
    std::mt19937 rng(2);
    std::uniform_real_distribution<float> uni(0.05f, 0.95f);
    const int charts = chartCount(surface());
    const float h = 1e-3f;
    const float scale = surfaceBounds(surface()).diagonal();
    for (int i = 0; i < 500; ++i) {
        const ChartPoint at{static_cast<int>(rng() % static_cast<unsigned>(charts)), uni(rng),
                            uni(rng)};
        const SurfaceSample s = evaluate(surface(), at);
        const glm::vec3 du = (evaluate(surface(), {at.chart, at.u + h, at.v}).P -
                              evaluate(surface(), {at.chart, at.u - h, at.v}).P) /
                             (2.0f * h);
        const glm::vec3 dv = (evaluate(surface(), {at.chart, at.u, at.v + h}).P -
                              evaluate(surface(), {at.chart, at.u, at.v - h}).P) /
                             (2.0f * h);
        ASSERT_LE(glm::length(du - s.dPdu), 2e-3f * scale + 2e-2f * glm::length(s.dPdu))
            << named().name << " chart " << at.chart;
        ASSERT_LE(glm::length(dv - s.dPdv), 2e-3f * scale + 2e-2f * glm::length(s.dPdv))
            << named().name << " chart " << at.chart;
    }
}

TEST_P(SurfaceProperties, ChartsCoverTheUnitSquareWithoutOverlap) {
    // Interior points of a grid over every chart must all land on distinct surface points.
    const int charts = chartCount(surface());
    const int n = charts > 200 ? 4 : 12;
    const float scale = surfaceBounds(surface()).diagonal();
    const float cell = 1e-4f * scale;
    std::map<std::tuple<long, long, long>, ChartPoint> seen;
    for (int chart = 0; chart < charts; ++chart) {
        for (int j = 0; j < n; ++j) {
            for (int i = 0; i < n; ++i) {
                const ChartPoint at{chart, (i + 0.5f) / n, (j + 0.5f) / n};
                const glm::vec3 p = evaluate(surface(), at).P;
                ASSERT_TRUE(std::isfinite(p.x + p.y + p.z));
                auto key = std::make_tuple(std::lround(p.x / cell), std::lround(p.y / cell),
                                           std::lround(p.z / cell));
                auto [it, inserted] = seen.emplace(key, at);
                EXPECT_TRUE(inserted) << named().name << ": chart " << chart << " (" << at.u << ", "
                                      << at.v << ") lands on chart " << it->second.chart << " ("
                                      << it->second.u << ", " << it->second.v << ")";
            }
        }
    }
}

TEST_P(SurfaceProperties, RayHitsEvaluateBackToTheHitPoint) {
    const SurfaceRayScene rays(surface());
    const Bounds3 b = surfaceBounds(surface());
    const float scale = b.diagonal();
    std::mt19937 rng(3);
    std::normal_distribution<float> gauss;
    std::uniform_real_distribution<float> uni(-0.5f, 0.5f);
    int hits = 0, refined = 0;
    for (int i = 0; i < 3000; ++i) {
        glm::vec3 dir(gauss(rng), gauss(rng), gauss(rng));
        dir = glm::normalize(dir);
        const glm::vec3 target =
            b.center() + glm::vec3(uni(rng), uni(rng), uni(rng)) * (b.hi - b.lo);
        const glm::vec3 org = target - dir * (2.0f * scale);
        SurfaceHit hit;
        if (!rays.intersect(org, dir, 0.0f, 1e30f, hit)) continue;
        ++hits;
        refined += hit.refined;
        ASSERT_GE(hit.at.chart, 0);
        ASSERT_LT(hit.at.chart, chartCount(surface()));
        ASSERT_GE(hit.at.u, 0.0f);
        ASSERT_LE(hit.at.u, 1.0f);
        const glm::vec3 p = evaluate(surface(), hit.at).P;
        ASSERT_LE(glm::length(p - (org + hit.t * dir)), 1e-4f * scale) << named().name;
    }
    EXPECT_GT(hits, 50) << named().name;
    EXPECT_GE(refined, hits * 95 / 100)
        << named().name << ": Newton refinement should converge almost always";
}

std::string surfaceName(const ::testing::TestParamInfo<int>& param) {
    static const std::vector<NamedSurface>& names = *new std::vector<NamedSurface>(allSurfaces());
    return names[static_cast<size_t>(param.param)].name;
}

INSTANTIATE_TEST_SUITE_P(AllTypes, SurfaceProperties, ::testing::Range(0, 9), surfaceName);

TEST(SphereRays, MatchTheAnalyticIntersection) {
    const Surface sphere = Sphere{2.0f};
    const SurfaceRayScene rays(sphere);
    std::mt19937 rng(4);
    std::uniform_real_distribution<float> uni(-1.9f, 1.9f);
    for (int i = 0; i < 500; ++i) {
        const glm::vec3 org(uni(rng), uni(rng), 10.0f);
        const glm::vec3 dir(0, 0, -1);
        SurfaceHit hit;
        const float r2 = org.x * org.x + org.y * org.y;
        if (r2 > 3.6f) continue;
        ASSERT_TRUE(rays.intersect(org, dir, 0.0f, 100.0f, hit));
        const float expected = 10.0f - std::sqrt(4.0f - r2);
        EXPECT_NEAR(hit.t, expected, 2e-4f);
    }
}

// The scene is built by the first query, whichever thread asks: queries racing from many
// threads at once on a scene nobody has used yet all see it whole (the analytic answer).
TEST(SphereRays, FirstQueriesFromManyThreadsAtOnce) {
    const Surface sphere = Sphere{2.0f};
    for (int round = 0; round < 4; ++round) {
        const SurfaceRayScene rays(sphere);
        std::vector<float> t(64, -1.0f);
        std::vector<std::thread> threads;
        for (int k = 0; k < 8; ++k)
            threads.emplace_back([&, k] {
                for (int i = k; i < 64; i += 8) {
                    const float x = -1.5f + 3.0f * static_cast<float>(i) / 63.0f;
                    SurfaceHit hit;
                    if (rays.intersect({x, 0.0f, 10.0f}, {0, 0, -1}, 0.0f, 100.0f, hit))
                        t[static_cast<size_t>(i)] = hit.t;
                }
            });
        for (std::thread& th : threads) th.join();
        for (int i = 0; i < 64; ++i) {
            const float x = -1.5f + 3.0f * static_cast<float>(i) / 63.0f;
            EXPECT_NEAR(t[static_cast<size_t>(i)], 10.0f - std::sqrt(4.0f - x * x), 2e-4f)
                << "ray " << i << ", round " << round;
        }
    }
}

TEST(SphereRays, OcclusionStreamsAnswerEachRayByItsSegment) {
    // 150 rays (traced in sets of 64) along z at random (x, y): blocked exactly when the
    // ray's line meets the sphere of radius 2 within its segment [0, tfar], the segment
    // starting at z = 10 and reaching z = 10 - tfar. Rays marked inactive answer 0.
    const Surface sphere = Sphere{2.0f};
    const SurfaceRayScene rays(sphere);
    constexpr int n = 150;
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> uni(-2.6f, 2.6f);
    std::vector<float> ox(n), oy(n), oz(n, 10.0f), dx(n, 0.0f), dy(n, 0.0f), dz(n, -1.0f);
    std::vector<uint8_t> active(n), blocked(n, 7);
    for (int i = 0; i < n; ++i) {
        ox[i] = uni(rng), oy[i] = uni(rng);
        active[i] = i % 5 != 2;
    }
    // Short segments stop at z = 10 - 7.5 = 2.5, above the sphere's top (z = 2): none hit.
    for (float tfar : {7.5f, 100.0f}) {
        const float* org[3] = {ox.data(), oy.data(), oz.data()};
        const float* dir[3] = {dx.data(), dy.data(), dz.data()};
        rays.occluded(org, dir, active.data(), n, 0.0f, tfar, blocked.data());
        int hits = 0;
        for (int i = 0; i < n; ++i) {
            const float r = std::sqrt(ox[i] * ox[i] + oy[i] * oy[i]);
            // Away from the silhouette by more than the tessellation's sag.
            if (std::fabs(r - 2.0f) < 0.01f) continue;
            const bool expected = active[i] && tfar > 8.0f && r < 2.0f;
            EXPECT_EQ(blocked[i], expected ? 1 : 0) << "ray " << i << " tfar " << tfar;
            hits += blocked[i];
        }
        if (tfar > 8.0f) {
            EXPECT_GT(hits, 30);
        }
    }
}

// escapes() at its boundaries: a plane's ray parallel to it from just above escapes, one
// from on it or tilted the least bit toward it does not; a sphere's ray from its surface
// itself or a millionth of its radius outside does not (the vertices' rounding margin), one
// tangent from a two-thousandth outside it does; and no ray escapes a torus, whose shape
// the test does not know.
TEST(SurfaceRays, EscapeHoldsOnlyWhereTheShapeRulesOutAHit) {
    const Surface plane = Plane{4.0f, 4.0f};
    const SurfaceRayScene planeRays(plane);
    EXPECT_TRUE(planeRays.escapes({0.3f, 1e-6f, 0.2f}, {1.0f, 0.0f, 0.0f}));
    EXPECT_TRUE(planeRays.escapes({0.3f, 0.5f, 0.2f}, {0.0f, 1.0f, 0.0f}));
    EXPECT_TRUE(planeRays.escapes({0.3f, -0.5f, 0.2f}, {0.6f, -0.8f, 0.0f}));
    EXPECT_FALSE(planeRays.escapes({0.3f, 0.0f, 0.2f}, {0.0f, 1.0f, 0.0f}));
    EXPECT_FALSE(planeRays.escapes({0.3f, 0.5f, 0.2f}, {1.0f, -1e-6f, 0.0f}));
    EXPECT_FALSE(planeRays.escapes({0.3f, -0.5f, 0.2f}, {0.0f, 1e-6f, 1.0f}));

    const Surface sphere = Sphere{2.0f};
    const SurfaceRayScene sphereRays(sphere);
    EXPECT_FALSE(sphereRays.escapes({2.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}));
    EXPECT_FALSE(sphereRays.escapes({2.000002f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}));
    EXPECT_TRUE(sphereRays.escapes({2.001f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}));
    EXPECT_TRUE(sphereRays.escapes({0.0f, 0.0f, -3.0f}, {0.0f, 0.6f, -0.8f}));
    EXPECT_FALSE(sphereRays.escapes({2.001f, 0.0f, 0.0f}, {-1e-3f, 1.0f, 0.0f}));
    EXPECT_FALSE(sphereRays.escapes({0.5f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}));  // inside

    const Surface torus = Torus{1.0f, 0.25f};
    const SurfaceRayScene torusRays(torus);
    EXPECT_FALSE(torusRays.escapes({0.0f, 5.0f, 0.0f}, {0.0f, 1.0f, 0.0f}));
}

// Against Embree itself: over random rays near a plane and a sphere, no ray escapes() lets
// through meets the tessellation (intersect() traces them all), while many of the others
// do; and occluded(), which answers escaping rays without tracing them, agrees with
// intersect() on every ray.
TEST(SurfaceRays, EscapingRaysNeverMeetTheTessellation) {
    const Surface plane = Plane{6.0f, 6.0f}, sphere = Sphere{1.5f};
    for (const Surface* surface : {&plane, &sphere}) {
        const SurfaceRayScene rays(*surface);
        constexpr int n = 400;
        std::mt19937 rng(11);
        std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
        std::vector<float> o[3], d[3];
        for (int k = 0; k < 3; ++k) o[k].resize(n), d[k].resize(n);
        int escaping = 0, hitting = 0;
        std::vector<uint8_t> expected(n);
        for (int i = 0; i < n; ++i) {
            glm::vec3 org(2.0f * uni(rng), 0.3f * uni(rng), 2.0f * uni(rng));
            if (std::holds_alternative<Sphere>(*surface))
                org = glm::normalize(org + glm::vec3(0.0f, 0.5f, 0.0f)) *
                      (1.5f + 0.01f * (uni(rng) + 1.0f));
            const glm::vec3 dir = glm::normalize(glm::vec3(uni(rng), uni(rng), uni(rng)));
            for (int k = 0; k < 3; ++k) o[k][i] = org[k], d[k][i] = dir[k];
            SurfaceHit hit;
            const bool meets = rays.intersect(org, dir, 0.0f, 100.0f, hit);
            expected[static_cast<size_t>(i)] = meets ? 1 : 0;
            if (rays.escapes(org, dir)) {
                ++escaping;
                EXPECT_FALSE(meets) << surfaceTypeName(*surface) << " ray " << i;
            }
            hitting += meets ? 1 : 0;
        }
        EXPECT_GT(escaping, n / 4) << surfaceTypeName(*surface);
        EXPECT_GT(hitting, n / 8) << surfaceTypeName(*surface);
        const float* org[3] = {o[0].data(), o[1].data(), o[2].data()};
        const float* dir[3] = {d[0].data(), d[1].data(), d[2].data()};
        std::vector<uint8_t> blocked(n, 7);
        rays.occluded(org, dir, nullptr, n, 0.0f, 100.0f, blocked.data());
        for (int i = 0; i < n; ++i)
            EXPECT_EQ(blocked[static_cast<size_t>(i)], expected[static_cast<size_t>(i)])
                << surfaceTypeName(*surface) << " ray " << i;
    }
}

TEST(SphereGeometry, PolesHaveExactNormals) {
    const Sphere s{1.0f};
    EXPECT_NEAR(s.evaluate(0, 0.3f, 1.0f).N.y, 1.0f, 1e-6f);
    EXPECT_NEAR(s.evaluate(0, 0.7f, 0.0f).N.y, -1.0f, 1e-6f);
}

TEST(TeapotGeometry, CollapsedEdgesStillHaveNormals) {
    const BezierPatches teapot = loadBezierPatches(sourcePath("examples/teapot/teapot.patches"));
    ASSERT_EQ(teapot.chartCount(), 32);
    // Patch 20 is the lid's top: its v = 0 row is one point.
    for (float u : {0.0f, 0.25f, 0.5f, 1.0f}) {
        const SurfaceSample s = teapot.evaluate(20, u, 0.0f);
        EXPECT_NEAR(glm::length(s.N), 1.0f, 1e-4f);
        EXPECT_GT(s.N.y, 0.9f) << "the lid's top faces up";
    }
}

TEST(SubdivGeometry, NgonFacesSplitIntoSubfaceCharts) {
    const SubdivSurface vase(loadObjCage(sourcePath("examples/vase/meshes/vase.obj")),
                             SubdivScheme::Catmark, "vase");
    // 88 quads, and two octagons of 8 sub-faces each.
    EXPECT_EQ(vase.chartCount(), 88 + 16);
    EXPECT_EQ(vase.chartFace(88), 88);
    EXPECT_EQ(vase.chartFace(88 + 8), 89);
}

TEST(SubdivGeometry, LimitSurfaceLiesInsideTheCage) {
    // A Catmull-Clark limit surface shrinks away from the convex cage's vertices.
    const SubdivSurface octa(loadObjCage(sourcePath("tests/data/meshes/octahedron.obj")),
                             SubdivScheme::Loop, "octa");
    for (int chart = 0; chart < octa.chartCount(); ++chart) {
        const glm::vec3 p = octa.evaluate(chart, 0.0f, 0.0f).P;
        EXPECT_LT(glm::length(p), 1.0f - 1e-3f);
        EXPECT_GT(glm::length(p), 0.3f);
    }
}

TEST(PointGeometry, ChartPointInvertsEvaluation) {
    const PointCloud cloud = loadPointCloud(sourcePath("tests/data/meshes/points.txt"));
    for (int chart = 0; chart < cloud.chartCount(); ++chart) {
        for (float u : {0.1f, 0.5f, 0.9f}) {
            for (float v : {0.05f, 0.3f, 0.8f}) {
                const ChartPoint back = cloud.chartPointOf(chart, cloud.evaluate(chart, u, v).P);
                EXPECT_NEAR(back.u, u, 1e-5f);
                EXPECT_NEAR(back.v, v, 1e-5f);
            }
        }
    }
}

}  // namespace
}  // namespace mpshade
