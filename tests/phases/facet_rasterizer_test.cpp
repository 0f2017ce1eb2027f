// The facet rasterizer (facet_rasterizer.h): watertight shared edges with samples exactly
// on vertices and edges, the opaque depth test against the k-buffer, sub-pixel facets,
// degenerate and culled facets, and work past a deadline.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "phases/facet_rasterizer.h"
#include "phases/fixed_point_warp.h"
#include "scene/scene.h"
#include "scene_fixtures.h"

namespace mpshade {
namespace {

using test::directionNear;
using test::lookAt;
using test::writeBlobScene;

// A grid of vertices on exact sub-pixel positions (12 x 9 of them 3 pixels apart, unless
// asked otherwise), two triangles per cell with alternating splits and windings (as
// different charts would have), and samples on the 1/4-pixel lattice (16 per pixel, or the
// first `spp` of them in a scattered order), so many land exactly on vertices and edges.
struct GridFixture {
    int gw = 12, gh = 9, W = 40, H = 30, spp = 16;
    float cell = 3.0f;  // pixels, a multiple of 1/4
    FacetMesh mesh;
    WarpedVertices warped;
    std::shared_ptr<SampleLayout> layout;
    GridFixture() { build(); }
    // Sub-pixel cells: every facet's box holds only a few samples.
    GridFixture(int columns, int rows, float cellPixels, int samplesPerPixel)
        : gw(columns), gh(rows), spp(samplesPerPixel), cell(cellPixels) {
        build();
    }
    void build() {
        std::mt19937 rng(3);
        const int amplitude = static_cast<int>(40 * cell / 3.0f);
        std::uniform_int_distribution<int> jitter(-amplitude, amplitude);
        for (int j = 0; j < gh; ++j)
            for (int i = 0; i < gw; ++i) {
                const bool inner = i > 0 && j > 0 && i < gw - 1 && j < gh - 1;
                // Every other inner vertex stays on the lattice, on samples and edges.
                const bool moved = inner && (i + j) % 2 == 0;
                warped.x.push_back(static_cast<int32_t>(256 * (2 + cell * i)) +
                                   (moved ? jitter(rng) : 0));
                warped.y.push_back(static_cast<int32_t>(256 * (2 + cell * j)) +
                                   (moved ? jitter(rng) : 0));
                warped.invDepth.push_back(0.2f + 0.001f * i);
                mesh.qx.push_back(0), mesh.qy.push_back(0), mesh.qz.push_back(0);
            }
        for (int j = 0; j + 1 < gh; ++j)
            for (int i = 0; i + 1 < gw; ++i) {
                const uint32_t a = j * gw + i, b = a + 1, c = a + gw + 1, d = a + gw;
                if ((i + j) % 2) {
                    mesh.positionIndex.insert(mesh.positionIndex.end(), {a, b, c, a, c, d});
                } else {
                    mesh.positionIndex.insert(mesh.positionIndex.end(), {b, a, d, b, d, c});
                }
            }
        mesh.attributeIndex = mesh.positionIndex;
        std::vector<float> xy;
        for (int py = 0; py < H; ++py)
            for (int px = 0; px < W; ++px)
                for (int k = 0; k < spp; ++k) {
                    const int q = spp == 16 ? k : (5 * k + 3 * (px + py)) % 16;
                    xy.push_back(px + 0.25f * (q % 4)), xy.push_back(py + 0.25f * (q / 4));
                }
        layout = std::make_shared<SampleLayout>(W, H, spp, xy);
    }
    // Inside the grid: the convex hull of the border (an axis-aligned rectangle).
    int inside(size_t s) const {
        const float x0 = 2.0f, x1 = 2 + cell * (gw - 1.0f), y0 = 2.0f, y1 = 2 + cell * (gh - 1.0f);
        const float x = layout->x(s), y = layout->y(s);
        if (x > x0 && x < x1 && y > y0 && y < y1) return 1;
        if (x < x0 || x > x1 || y < y0 || y > y1) return 0;
        return -1;  // on the hull: either
    }
};

TEST(FacetRasterizer, SharedEdgesAreWatertight) {
    // Translucent: every facet covering a sample is kept (the k-buffer holds 4), so a
    // sample covered twice or not at all shows in its count. Tiles of several sizes, so
    // facets straddle tile edges at different places (5: on the grid's own lines too).
    GridFixture g;
    for (int tileSize : {5, 16, 32}) {
        VisibilityBuffer vis;
        RasterStats stats;
        RasterOptions options;
        options.layers = 4;
        options.tileSize = tileSize;
        rasterizeFacets({{&g.mesh, &g.warped, nullptr, false}}, *g.layout, 1e30f, options, vis,
                        stats);
        ASSERT_EQ(vis.layers, 4);
        int interior = 0;
        for (size_t s = 0; s < g.layout->count(); ++s) {
            const int in = g.inside(s);
            if (in == 1) {
                ++interior;
                ASSERT_EQ(vis.count[s], 1) << "tiles of " << tileSize << ", sample at ("
                                           << g.layout->x(s) << ", " << g.layout->y(s) << ")";
            } else if (in == 0) {
                ASSERT_EQ(vis.count[s], 0);
            }
        }
        EXPECT_GT(interior, 10000);
        EXPECT_EQ(stats.facetsDegenerate, 0u);
    }
}

TEST(FacetRasterizer, OpaqueDepthTestCoversTheSameSamples) {
    // The opaque path (one layer, the vectorized depth test -- by hand in AVX-512 where the
    // processor has it --, whole tiles skipping the edge tests) must cover exactly the
    // samples the k-buffer path does, at the same depth bits, and keep the nearest facet:
    // here depth falls with x, so the facet with the largest 1/depth wins.
    GridFixture g;
    VisibilityBuffer layered, opaque;
    RasterStats a, b;
    RasterOptions options;
    options.layers = 4;
    rasterizeFacets({{&g.mesh, &g.warped, nullptr, false}}, *g.layout, 1e30f, options, layered, a);
    rasterizeFacets({{&g.mesh, &g.warped, nullptr, true}}, *g.layout, 1e30f, options, opaque, b);
    ASSERT_EQ(opaque.layers, 1);
    for (size_t s = 0; s < g.layout->count(); ++s) {
        ASSERT_EQ(opaque.count[s], layered.count[s]) << s;
        if (opaque.count[s]) {
            ASSERT_EQ(opaque.facet[s], layered.facet[s * layered.layers]);
            // The same depth plane, evaluated alike (unfused) in the vector sample test.
            ASSERT_EQ(opaque.invDepth[s], layered.invDepth[s * layered.layers]) << s;
        }
    }
    // Surfaces beyond the far plane are not seen: 1 / depth here is 0.2 .. 0.211.
    VisibilityBuffer far;
    rasterizeFacets({{&g.mesh, &g.warped, nullptr, true}}, *g.layout, 4.0f, options, far, b);
    for (size_t s = 0; s < g.layout->count(); ++s) ASSERT_EQ(far.count[s], 0);
}

TEST(FacetRasterizer, SubPixelFacetsCoverEverySampleOnce) {
    // Facets a little under a pixel across, at 1, 2 and 4 samples per pixel, so the opaque
    // path tests most of them sample by sample (their boxes hold at most 8 samples): the
    // translucent path, which keeps every facet covering a sample, must find every interior
    // sample covered exactly once, and the opaque path must give each the same facet.
    for (int spp : {1, 2, 4}) {
        GridFixture g(50, 38, 0.75f, spp);
        VisibilityBuffer layered, opaque;
        RasterStats a, b;
        RasterOptions options;
        options.layers = 4;
        options.tileSize = spp == 2 ? 7 : 16;  // facets across tile edges at odd places too
        rasterizeFacets({{&g.mesh, &g.warped, nullptr, false}}, *g.layout, 1e30f, options, layered,
                        a);
        rasterizeFacets({{&g.mesh, &g.warped, nullptr, true}}, *g.layout, 1e30f, options, opaque,
                        b);
        int interior = 0;
        for (size_t s = 0; s < g.layout->count(); ++s) {
            const int in = g.inside(s);
            if (in == 1) {
                ++interior;
                ASSERT_EQ(layered.count[s], 1) << spp << " spp, sample at (" << g.layout->x(s)
                                               << ", " << g.layout->y(s) << ")";
            } else if (in == 0) {
                ASSERT_EQ(layered.count[s], 0);
            }
            ASSERT_EQ(opaque.count[s], layered.count[s]) << spp << " spp, sample " << s;
            if (opaque.count[s]) {
                ASSERT_EQ(opaque.facet[s], layered.facet[s * layered.layers]);
                ASSERT_EQ(opaque.invDepth[s], layered.invDepth[s * layered.layers]);
            }
        }
        EXPECT_GT(interior, 700 * spp);
        EXPECT_EQ(a.fragments, b.fragments);
    }
}

TEST(FacetRasterizer, SkipsDegenerateAndCulledFacets) {
    FacetMesh mesh;
    WarpedVertices warped;
    auto vertex = [&](int32_t x, int32_t y, bool culled) {
        warped.x.push_back(culled ? WarpedVertices::kCulled : x), warped.y.push_back(y),
            warped.invDepth.push_back(0.5f);
        mesh.qx.push_back(0), mesh.qy.push_back(0), mesh.qz.push_back(0);
    };
    vertex(256, 256, 0), vertex(2560, 256, 0), vertex(256, 2560, 0);    // a real facet
    vertex(512, 512, 0), vertex(1024, 1024, 0), vertex(2048, 2048, 0);  // collinear: zero area
    vertex(700, 700, 0), vertex(700, 700, 0), vertex(700, 700, 0);      // a point
    vertex(300, 300, 0), vertex(2000, 300, 1),
        vertex(300, 2000, 0);  // a vertex behind the near plane, and no warp to clip with
    for (uint32_t k = 0; k < 12; ++k) mesh.positionIndex.push_back(k);
    mesh.attributeIndex = mesh.positionIndex;
    const SampleLayout layout(12, 12, 4, 0u);
    VisibilityBuffer vis;
    RasterStats stats;
    rasterizeFacets({{&mesh, &warped, nullptr, true}}, layout, 1e30f, {}, vis, stats);
    EXPECT_EQ(stats.facets, 4u);
    EXPECT_EQ(stats.facetsDegenerate, 2u);
    EXPECT_EQ(stats.facetsCulled, 1u);
    EXPECT_GT(stats.facetsBinned, 0u);
    int covered = 0;
    for (size_t s = 0; s < vis.count.size(); ++s)
        if (vis.count[s]) {
            ++covered;
            EXPECT_EQ(vis.facet[s], 0u);
            EXPECT_TRUE(std::isfinite(vis.invDepth[s]));
        }
    EXPECT_GT(covered, 0);
}

TEST(FacetRasterizer, WorkPastTheDeadlineIsAbandoned) {
    // A deadline already past: nothing is binned or drawn and the result says so. One an
    // hour away: the timed path draws exactly what the untimed one does.
    GridFixture g;
    for (bool opaque : {true, false}) {
        VisibilityBuffer untimed, late, early;
        RasterStats a, b, c;
        RasterOptions options;
        rasterizeFacets({{&g.mesh, &g.warped, nullptr, opaque}}, *g.layout, 1e30f, options, untimed,
                        a);
        ASSERT_FALSE(a.abandoned);
        ASSERT_GT(a.fragments, 10000u);
        options.deadline = std::chrono::steady_clock::now() - std::chrono::seconds(1);
        rasterizeFacets({{&g.mesh, &g.warped, nullptr, opaque}}, *g.layout, 1e30f, options, late,
                        b);
        EXPECT_TRUE(b.abandoned);
        EXPECT_EQ(b.facetsBinned, 0u);
        EXPECT_EQ(b.fragments, 0u);
        options.deadline = std::chrono::steady_clock::now() + std::chrono::hours(1);
        rasterizeFacets({{&g.mesh, &g.warped, nullptr, opaque}}, *g.layout, 1e30f, options, early,
                        c);
        EXPECT_FALSE(c.abandoned);
        EXPECT_EQ(c.fragments, a.fragments);
        EXPECT_EQ(c.facetsBinned, a.facetsBinned);
        EXPECT_TRUE(std::equal(early.count.begin(), early.count.end(), untimed.count.begin()));
    }
}

}  // namespace
}  // namespace mpshade
