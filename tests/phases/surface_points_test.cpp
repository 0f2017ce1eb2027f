// Where shadeSurfacePoints puts each point: position and chart footprint against a ray-facet
// intersection worked in double precision, and runs of points on one facet (taken four at a
// time in vectors, the rest one by one) against the same points shaded alone.
#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "phases/dynamic_frame.h"
#include "phases/surface_points.h"
#include "test_support.h"

namespace mpshade {
namespace {

using test::Frame;
using test::sourcePath;
using DVec = std::array<double, 3>;

DVec sub(const DVec& a, const DVec& b) {
    return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
DVec cross(const DVec& a, const DVec& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const DVec& a, const DVec& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
DVec toD(const glm::vec3& v) {
    return {v.x, v.y, v.z};
}

// The ball scene with wood (three stored channels) for its plastic, written to the test's
// own folder.
std::string woodenBall() {
    std::ifstream in(sourcePath("tests/data/scenes/ball.json"));
    std::stringstream text;
    text << in.rdbuf();
    std::string scene = text.str();
    const std::string plastic = "../../../examples/shaders/plastic.sl";
    const size_t at = scene.find(plastic);
    EXPECT_NE(at, std::string::npos);
    scene.replace(at, plastic.size(), sourcePath("examples/shaders/wood.sl"));
    const std::string path = test::testFolder("surface_points") + "wooden_ball.json";
    std::ofstream(path) << scene;
    return path;
}

// The wooden ball seen by its camera at frame 0, as a shader map, and the view the dynamic
// phase would give it (object space).
struct BallView {
    Frame f{woodenBall(), Representation::ShaderMap, 64, 48};
    ObjectView view;
    BallView() {
        const CameraState& c = f.state.camera;
        const ObjectState& o = f.state.objects[0];
        const float tx = c.tanHalfFovY * c.aspect, ty = c.tanHalfFovY;
        const glm::mat3 toObject(o.worldToObject);
        view.rep = f.reps[0].get();
        EXPECT_NE(view.rep->map, nullptr);
        view.uniforms = &f.state.uniforms[0];
        view.eye = o.eye;
        view.d0 = toObject * (c.forward - tx * c.right + ty * c.up);
        view.dx = toObject * ((2.0f * tx / static_cast<float>(c.width)) * c.right);
        view.dy = toObject * ((-2.0f * ty / static_cast<float>(c.height)) * c.up);
        view.footprintScale = 1.0f;
    }
    const FacetMesh& mesh() const { return view.rep->mesh; }
    std::array<DVec, 3> corners(uint32_t facet) const {
        std::array<DVec, 3> p;
        for (int k = 0; k < 3; ++k) {
            const uint32_t i = mesh().positionIndex[3 * facet + k];
            p[k] = toD(mesh().format.dequantize(mesh().qx[i], mesh().qy[i], mesh().qz[i]));
        }
        return p;
    }
    DVec ray(double x, double y) const {
        const DVec d0 = toD(view.d0), dx = toD(view.dx), dy = toD(view.dy);
        return {d0[0] + x * dx[0] + y * dy[0], d0[1] + x * dx[1] + y * dy[1],
                d0[2] + x * dx[2] + y * dy[2]};
    }
    // Barycentric weights (b1, b2) where the ray through (x, y) meets the facet's plane.
    std::array<double, 2> weightsAt(uint32_t facet, double x, double y) const {
        const auto p = corners(facet);
        const DVec e1 = sub(p[1], p[0]), e2 = sub(p[2], p[0]), d = ray(x, y);
        const DVec s = sub(toD(view.eye), p[0]);
        const DVec h = cross(d, e2), q = cross(s, e1);
        const double a = dot(e1, h);
        return {dot(s, h) / a, dot(d, q) / a};
    }
    // The screen position whose ray meets the facet at weights (b1, b2), and how squarely
    // (the cosine between the ray and the facet's normal); false behind the eye.
    bool screenAt(uint32_t facet, double b1, double b2, double& x, double& y,
                  double& cosine) const {
        const auto p = corners(facet);
        const DVec e1 = sub(p[1], p[0]), e2 = sub(p[2], p[0]);
        const DVec Q = {p[0][0] + b1 * e1[0] + b2 * e2[0], p[0][1] + b1 * e1[1] + b2 * e2[1],
                        p[0][2] + b1 * e1[2] + b2 * e2[2]};
        const DVec w = sub(Q, toD(view.eye));
        // x dx + y dy - l w = -d0, by Cramer's rule.
        const DVec dx = toD(view.dx), dy = toD(view.dy), d0 = toD(view.d0);
        const DVec mw = {-w[0], -w[1], -w[2]}, rhs = {-d0[0], -d0[1], -d0[2]};
        const double det = dot(dx, cross(dy, mw));
        if (std::fabs(det) < 1e-12) return false;
        x = dot(rhs, cross(dy, mw)) / det;
        y = dot(dx, cross(rhs, mw)) / det;
        const double l = dot(dx, cross(dy, rhs)) / det;
        const DVec n = cross(e1, e2);
        cosine = std::fabs(dot(n, w)) / std::sqrt(dot(n, n) * dot(w, w));
        return l > 0.0;
    }
};

constexpr std::array<std::array<double, 2>, 9> kWeights = {{{0.2, 0.2},
                                                            {0.6, 0.2},
                                                            {0.2, 0.6},
                                                            {0.33, 0.33},
                                                            {0.1, 0.45},
                                                            {0.45, 0.1},
                                                            {0.7, 0.15},
                                                            {0.15, 0.7},
                                                            {0.4, 0.4}}};

struct Shaded {
    std::vector<float> P[3];
    std::vector<ProbeQuery> queries;
};

Shaded shade(const BallView& b, const std::vector<uint32_t>& facet, const std::vector<float>& x,
             const std::vector<float>& y) {
    const size_t n = facet.size();
    SurfaceShadingScratch scratch;
    SurfaceShadingCounters counters;
    std::vector<float> color(3 * n), opacity(3 * n);
    std::vector<uint8_t> missed(n);
    shadeSurfacePoints(b.view, DynamicOptions{}.probe, false, {facet.data(), x.data(), y.data(), n},
                       color.data(), opacity.data(), missed.data(), scratch, counters);
    Shaded s;
    for (int k = 0; k < 3; ++k) {
        const float* row = scratch.batch.row(ShadingBatch::P + k);
        s.P[k].assign(row, row + n);
    }
    s.queries.assign(scratch.queries.begin(), scratch.queries.begin() + static_cast<long>(n));
    return s;
}

// Facets of the ball that face the eye squarely enough for a finite difference, by index.
std::vector<uint32_t> facingFacets(const BallView& b, size_t count) {
    std::vector<uint32_t> out;
    const size_t facets = b.mesh().positionIndex.size() / 3;
    for (uint32_t f = 0; f < facets && out.size() < count; f += 7) {
        double x, y, cosine;
        if (b.screenAt(f, 0.33, 0.33, x, y, cosine) && cosine > 0.3) out.push_back(f);
    }
    return out;
}

TEST(SurfacePoints, PositionsAndFootprintsMatchARayFacetIntersectionInDoublePrecision) {
    const BallView b;
    ASSERT_NE(b.view.rep->map, nullptr);
    const std::vector<uint32_t> facets = facingFacets(b, 24);
    ASSERT_GE(facets.size(), 12u);
    std::vector<uint32_t> facet;
    std::vector<float> x, y;
    std::vector<std::array<double, 2>> weights;
    for (uint32_t f : facets)
        for (const auto& w : kWeights) {
            double sx, sy, cosine;
            ASSERT_TRUE(b.screenAt(f, w[0], w[1], sx, sy, cosine));
            facet.push_back(f);
            x.push_back(static_cast<float>(sx));
            y.push_back(static_cast<float>(sy));
            // The weights at the float position, as the engine sees it.
            weights.push_back(b.weightsAt(f, x.back(), y.back()));
        }
    const Shaded s = shade(b, facet, x, y);
    const FacetMesh& mesh = b.mesh();
    for (size_t i = 0; i < facet.size(); ++i) {
        SCOPED_TRACE(testing::Message() << "facet " << facet[i] << " point " << i);
        const auto p = b.corners(facet[i]);
        const double b1 = weights[i][0], b2 = weights[i][1];
        DVec Q;
        for (int k = 0; k < 3; ++k)
            Q[k] = p[0][k] + b1 * (p[1][k] - p[0][k]) + b2 * (p[2][k] - p[0][k]);
        // P within a thousandth of a pixel (its width at the point's distance).
        const DVec toQ = sub(Q, toD(b.view.eye)), d = b.ray(x[i], y[i]), dx = toD(b.view.dx);
        const double pixel = std::sqrt(dot(toQ, toQ) * dot(dx, dx) / dot(d, d));
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(s.P[k][i], Q[k], 1e-3 * pixel);
        const uint32_t* a = &mesh.attributeIndex[3 * facet[i]];
        const ChartPoint &c0 = mesh.attributeChartPoint[a[0]], &c1 = mesh.attributeChartPoint[a[1]],
                         &c2 = mesh.attributeChartPoint[a[2]];
        auto chartAt = [&](double sx, double sy) {
            const auto w = b.weightsAt(facet[i], sx, sy);
            return std::array<double, 2>{
                c0.u + w[0] * (double{c1.u} - c0.u) + w[1] * (double{c2.u} - c0.u),
                c0.v + w[0] * (double{c1.v} - c0.v) + w[1] * (double{c2.v} - c0.v)};
        };
        const ProbeQuery& q = s.queries[i];
        EXPECT_EQ(q.chart, c0.chart);
        // The footprint: central differences of the chart point over a thousandth of a pixel.
        const double h = 1e-3;
        const auto xp = chartAt(x[i] + h, y[i]), xm = chartAt(x[i] - h, y[i]);
        const auto yp = chartAt(x[i], y[i] + h), ym = chartAt(x[i], y[i] - h);
        const double want[4] = {(xp[0] - xm[0]) / (2 * h), (yp[0] - ym[0]) / (2 * h),
                                (xp[1] - xm[1]) / (2 * h), (yp[1] - ym[1]) / (2 * h)};
        const float got[4] = {q.dudx, q.dudy, q.dvdx, q.dvdy};
        double scale = 0.0;
        for (double w : want) scale = std::max(scale, std::fabs(w));
        ASSERT_GT(scale, 0.0);
        // The chart point within a thousandth of a pixel's footprint (float weights of a
        // small facet far from the eye lose digits to cancellation).
        const auto uv = chartAt(x[i], y[i]);
        EXPECT_NEAR(q.u, uv[0], 1e-3 * scale);
        EXPECT_NEAR(q.v, uv[1], 1e-3 * scale);
        for (int k = 0; k < 4; ++k)
            EXPECT_NEAR(got[k], want[k], 1e-3 * scale) << "derivative " << k;
    }
}

// Runs of 9, 5, 3, 1, 4, 8 and 2 points (one facet returning after another): vectors of four
// and the points after them give each point the bits it gets shaded alone.
TEST(SurfacePoints, RunsOfAnyLengthGiveEachPointTheBitsItGetsAlone) {
    const BallView b;
    ASSERT_NE(b.view.rep->map, nullptr);
    const std::vector<uint32_t> facets = facingFacets(b, 6);
    ASSERT_GE(facets.size(), 6u);
    const std::vector<std::pair<uint32_t, int>> runs = {
        {facets[0], 9}, {facets[1], 5}, {facets[0], 3}, {facets[2], 1},
        {facets[3], 4}, {facets[4], 8}, {facets[5], 2}};
    std::vector<uint32_t> facet;
    std::vector<float> x, y;
    for (const auto& [f, length] : runs)
        for (int k = 0; k < length; ++k) {
            const auto& w = kWeights[static_cast<size_t>(k) % kWeights.size()];
            double sx, sy, cosine;
            ASSERT_TRUE(b.screenAt(f, w[0], w[1], sx, sy, cosine));
            facet.push_back(f);
            x.push_back(static_cast<float>(sx));
            y.push_back(static_cast<float>(sy));
        }
    const Shaded together = shade(b, facet, x, y);
    for (size_t i = 0; i < facet.size(); ++i) {
        SCOPED_TRACE(testing::Message() << "point " << i);
        const Shaded alone = shade(b, {facet[i]}, {x[i]}, {y[i]});
        for (int k = 0; k < 3; ++k) EXPECT_EQ(together.P[k][i], alone.P[k][0]);
        EXPECT_EQ(std::memcmp(&together.queries[i], &alone.queries[0], sizeof(ProbeQuery)), 0);
    }
}

// A point that lies at the eye (the eye on one of its facet's corners) has no direction
// from the eye (it would be 0); it takes its ray's. In a batch's vector part and its tail
// alike, beside points of another facet.
TEST(SurfacePoints, APointAtTheEyeTakesItsRaysDirection) {
    BallView b;
    const std::vector<uint32_t> facets = facingFacets(b, 2);
    ASSERT_GE(facets.size(), 2u);
    const uint32_t i0 = b.mesh().positionIndex[3 * facets[0]];
    b.view.eye = b.mesh().format.dequantize(b.mesh().qx[i0], b.mesh().qy[i0], b.mesh().qz[i0]);
    for (size_t n = 1; n <= 11; ++n) {
        std::vector<uint32_t> facet;
        std::vector<float> x, y;
        for (size_t i = 0; i < n; ++i) {
            facet.push_back(facets[i % 3 == 2 ? 1 : 0]);
            x.push_back(10.0f + 3.0f * static_cast<float>(i));
            y.push_back(20.0f + 1.5f * static_cast<float>(i));
        }
        SurfaceShadingScratch scratch;
        SurfaceShadingCounters counters;
        std::vector<float> color(3 * n), opacity(3 * n);
        std::vector<uint8_t> missed(n);
        shadeSurfacePoints(b.view, DynamicOptions{}.probe, false,
                           {facet.data(), x.data(), y.data(), n}, color.data(), opacity.data(),
                           missed.data(), scratch, counters);
        for (size_t i = 0; i < n; ++i) {
            SCOPED_TRACE(testing::Message() << n << " points, point " << i);
            float I[3];
            for (int k = 0; k < 3; ++k) I[k] = scratch.batch.row(ShadingBatch::I + k)[i];
            const DVec ray = b.ray(x[i], y[i]);
            const double len = std::sqrt(ray[0] * ray[0] + ray[1] * ray[1] + ray[2] * ray[2]);
            // Points of the other facet lie on their rays too, so theirs is the same.
            for (int k = 0; k < 3; ++k) EXPECT_NEAR(I[k], ray[k] / len, 1e-5);
        }
    }
}

}  // namespace
}  // namespace mpshade
