// Facets clipped at the near plane and the guard band (facet_clipping.h): watertight
// across the near plane, and on both axes of the guard band.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "dicing_view.h"
#include "phases/dicing.h"
#include "phases/facet_clipping.h"
#include "phases/facet_rasterizer.h"
#include "phases/fixed_point_warp.h"

namespace mpshade {
namespace {

using test::View;

TEST(FacetClipping, FacetsAcrossTheNearPlaneStayWatertight) {
    // A quad of two triangles lying on the floor, from a camera just above it: two of its
    // corners are behind the eye. Clipped, the two triangles must still cover every sample
    // of the visible floor exactly once (the translucent path counts every facet hit).
    FacetMesh mesh;
    Bounds3 b;
    b.extend(glm::vec3(-50, 0, -50));
    b.extend(glm::vec3(50, 0.001f, 50));
    mesh.format = FixedPointFormat::forBounds(b);
    for (const glm::vec3& p : {glm::vec3(-50, 0, -50), glm::vec3(50, 0, -50), glm::vec3(50, 0, 50),
                               glm::vec3(-50, 0, 50)}) {
        mesh.qx.push_back(mesh.format.quantize(p.x, 0));
        mesh.qy.push_back(mesh.format.quantize(p.y, 1));
        mesh.qz.push_back(mesh.format.quantize(p.z, 2));
    }
    mesh.positionIndex = {0, 2, 1, 0, 3, 2};  // the shared diagonal crosses the near plane
    mesh.attributeIndex = mesh.positionIndex;
    const View view(glm::vec3(3, 0.3f, 4), glm::vec3(-2, 0.1f, -6), 96, 54);
    const FixedPointWarp warp(glm::mat4(1.0f), view.camera, mesh.format);
    WarpedVertices warped;
    warp.warp(mesh.qx.data(), mesh.qy.data(), mesh.qz.data(), 4, warped);
    ASSERT_TRUE(warped.culled(0) || warped.culled(1) || warped.culled(2) || warped.culled(3));
    const SampleLayout layout(96, 54, 16, 3u);
    VisibilityBuffer vis;
    RasterStats stats;
    RasterOptions options;
    options.layers = 4;
    rasterizeFacets({{&mesh, &warped, &warp, false}}, layout, 1000.0f, options, vis, stats);
    EXPECT_GT(stats.facetsClipped, 0u);
    int floor = 0;
    for (size_t s = 0; s < layout.count(); ++s) {
        // Below the horizon the floor fills the view (it reaches 50 units out).
        const glm::vec3 d = view.camera.direction(layout.x(s), layout.y(s));
        if (d.y > -0.01f) continue;
        const float t = -0.3f / d.y;
        const glm::vec3 hit = view.camera.eye + t * d;
        if (std::fabs(hit.x) > 49.0f || std::fabs(hit.z) > 49.0f) continue;
        ++floor;
        ASSERT_EQ(vis.count[s], 1)
            << "sample " << s << " at (" << layout.x(s) << ", " << layout.y(s) << ")";
    }
    EXPECT_GT(floor, 20000);
}

// Is (x, y) inside triangle (a, b, c), and how far from its nearest edge line (pixels)?
bool insideTriangle(const glm::dvec2 v[3], double x, double y, double& edgeDistance) {
    int positive = 0, negative = 0;
    edgeDistance = 1e300;
    for (int e = 0; e < 3; ++e) {
        const glm::dvec2 a = v[e], b = v[(e + 1) % 3];
        const double cross = (b.x - a.x) * (y - a.y) - (b.y - a.y) * (x - a.x);
        edgeDistance = std::min(edgeDistance, std::fabs(cross) / glm::length(b - a));
        positive += cross > 0.0, negative += cross < 0.0;
    }
    return positive == 0 || negative == 0;
}

TEST(FacetClipping, GuardBandOnBothAxes) {
    // A square of two facets seen so close that it spans about 160 000 pixels each way,
    // and three more facets crossing the guard band (|x|, |y| <= 32768 pixels) on x only,
    // on y only, and on both. Clipped, every corner lies in the band, and the clipped
    // triangles cover exactly the points of the band the exact facet covers (points on a
    // grid through the band and just inside its edges, away from the facet's own edges);
    // the square's two halves share the corners where their diagonal leaves the band.
    FacetMesh mesh;
    Bounds3 b;
    b.extend(glm::vec3(-1, -1, -0.001f));
    b.extend(glm::vec3(1, 1, 0.001f));
    mesh.format = FixedPointFormat::forBounds(b);
    const glm::vec2 corners[] = {{-1, -1},   {1, -1},       {1, 1},          {-1, 1},  // square
                                 {-1, 0},    {0.2f, -0.2f}, {0.25f, 0.25f},            // x only
                                 {0, -1},    {0.2f, 0.2f},  {-0.25f, 0.25f},           // y only
                                 {-1, 0.9f}, {0.9f, -1},    {0.1f, 0.1f}};             // both
    for (const glm::vec2& c : corners) {
        mesh.qx.push_back(mesh.format.quantize(c.x, 0));
        mesh.qy.push_back(mesh.format.quantize(c.y, 1));
        mesh.qz.push_back(mesh.format.quantize(0.0f, 2));
    }
    mesh.positionIndex = {0, 1, 2, 0, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
    mesh.attributeIndex = mesh.positionIndex;
    View view(glm::vec3(0, 0, 5), glm::vec3(0.0f), 320, 240);
    view.camera.tanHalfFovY = 3e-4f;  // 1 object unit is about 80 000 pixels
    const FixedPointWarp warp(glm::mat4(1.0f), view.camera, mesh.format);
    WarpedVertices warped;
    warp.warp(mesh.qx.data(), mesh.qy.data(), mesh.qz.data(), mesh.qx.size(), warped);

    constexpr double G = FixedPointWarp::kGuardBand;
    std::vector<double> probes;
    for (double p = -G + 0.25; p < G; p += 997.0) probes.push_back(p);
    for (double p : {-G + 0.25, -G + 0.75, G - 0.75, G - 0.25}) probes.push_back(p);
    std::vector<std::vector<ScreenTriangle>> clipped;
    for (size_t f = 0; f < mesh.positionIndex.size(); f += 3) {
        const uint32_t* p = &mesh.positionIndex[f];
        glm::dvec2 exact[3];
        bool crossesX = false, crossesY = false;
        for (int i = 0; i < 3; ++i) {
            ASSERT_TRUE(warp.warpExact(mesh.qx[p[i]], mesh.qy[p[i]], mesh.qz[p[i]], exact[i].x,
                                       exact[i].y));
            crossesX |= std::fabs(exact[i].x) > G, crossesY |= std::fabs(exact[i].y) > G;
            ASSERT_EQ(warped.culled(p[i]), std::fabs(exact[i].x) > G || std::fabs(exact[i].y) > G);
        }
        if (f == 6) {
            EXPECT_TRUE(crossesX && !crossesY);
        } else if (f == 9) {
            EXPECT_TRUE(!crossesX && crossesY);
        } else if (f == 12) {
            EXPECT_TRUE(crossesX && crossesY);
        }
        ScreenTriangle out[6];
        const int n = clipFacet(warp, mesh, warped, p, out);
        ASSERT_GT(n, 0) << "facet " << f / 3;
        clipped.emplace_back(out, out + n);
        constexpr int32_t kBand = int32_t(G) * 256;
        for (const ScreenTriangle& t : clipped.back())
            for (int i = 0; i < 3; ++i) {
                ASSERT_LE(std::abs(t.x[i]), kBand) << "facet " << f / 3;
                ASSERT_LE(std::abs(t.y[i]), kBand) << "facet " << f / 3;
                ASSERT_GT(t.invDepth[i], 0.0f);
            }
        int inside = 0;
        for (double x : probes)
            for (double y : probes) {
                double distance;
                const bool in = insideTriangle(exact, x, y, distance);
                if (distance < 2.0) continue;
                bool covered = false;
                for (const ScreenTriangle& t : clipped.back()) {
                    glm::dvec2 v[3];
                    for (int i = 0; i < 3; ++i) v[i] = glm::dvec2(t.x[i], t.y[i]) / 256.0;
                    double unused;
                    covered |= insideTriangle(v, x, y, unused);
                }
                ASSERT_EQ(covered, in) << "facet " << f / 3 << " at (" << x << ", " << y << ")";
                inside += in;
            }
        EXPECT_GT(inside, 100) << "facet " << f / 3;
    }
    // The square's halves: each corner one makes on the diagonal, the other makes too.
    auto cornersOf = [&](int facet) {
        std::vector<std::pair<int32_t, int32_t>> c;
        for (const ScreenTriangle& t : clipped[facet])
            for (int i = 0; i < 3; ++i) c.emplace_back(t.x[i], t.y[i]);
        std::sort(c.begin(), c.end());  // the fan repeats its first corner: count each once
        c.erase(std::unique(c.begin(), c.end()), c.end());
        return c;
    };
    const auto lower = cornersOf(0), upper = cornersOf(1);
    int shared = 0;
    for (const auto& c : lower)
        if (std::find(upper.begin(), upper.end(), c) != upper.end()) ++shared;
    EXPECT_GE(shared, 2) << "the clipped diagonal's two ends";
}

}  // namespace
}  // namespace mpshade
