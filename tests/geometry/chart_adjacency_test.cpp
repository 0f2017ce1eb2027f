// Chart adjacency: seams of single-chart surfaces, shared cage edges, and continuity of
// points resolved across an edge.
#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "geometry/chart_adjacency.h"
#include "test_support.h"

namespace mpshade {
namespace {

TEST(ChartAdjacency, SphereSeamTorusAndPlane) {
    const Surface sphere = Sphere{1.0f};
    const ChartAdjacency s(sphere);
    EXPECT_EQ(s.link(0, 1).chart, 0);  // u = 1 meets u = 0
    EXPECT_EQ(s.link(0, 1).edge, 3);
    EXPECT_TRUE(s.link(0, 1).reversed);
    EXPECT_EQ(s.link(0, 0).chart, -1);  // the poles
    EXPECT_EQ(s.link(0, 2).chart, -1);

    const Surface torus = Torus{1.0f, 0.3f};
    const ChartAdjacency t(torus);
    EXPECT_EQ(t.link(0, 0).edge, 2);
    EXPECT_EQ(t.link(0, 1).edge, 3);

    const Surface plane = Plane{2.0f, 2.0f};
    const ChartAdjacency p(plane);
    for (int e = 0; e < 4; ++e) EXPECT_EQ(p.link(0, e).chart, -1);
    const ChartPoint clamped = p.resolve(0, 1.2f, -0.1f);
    EXPECT_EQ(clamped.u, 1.0f);
    EXPECT_EQ(clamped.v, 0.0f);
}

TEST(ChartAdjacency, SubdivQuadsLinkAcrossCageEdges) {
    const Surface vase =
        SubdivSurface(loadObjCage(test::sourcePath("examples/vase/meshes/vase.obj")),
                      SubdivScheme::Catmark, "vase");
    const ChartAdjacency adj(vase);
    int linked = 0, total = 0;
    for (int chart = 0; chart < chartCount(vase); ++chart)
        for (int e = 0; e < 4; ++e) {
            ++total;
            const ChartEdgeLink& l = adj.link(chart, e);
            if (l.chart < 0) continue;
            ++linked;
            // Links are symmetric.
            EXPECT_EQ(adj.link(l.chart, l.edge).chart, chart);
            EXPECT_EQ(adj.link(l.chart, l.edge).edge, e);
        }
    // Every edge links but the outer half-edges of the two octagons' sub-faces (2 x 16)
    // and the 16 quad edges beside them.
    EXPECT_EQ(total - linked, 48);
}

TEST(ChartAdjacency, ResolvedPointsContinueAcrossTheEdge) {
    const Surface vase =
        SubdivSurface(loadObjCage(test::sourcePath("examples/vase/meshes/vase.obj")),
                      SubdivScheme::Catmark, "vase");
    const ChartAdjacency adj(vase);
    const float scale = surfaceBounds(vase).diagonal();
    for (int chart = 0; chart < 88; ++chart) {  // the quad charts
        for (float along : {0.2f, 0.5f, 0.8f}) {
            // Just beyond edge 1 (u = 1): close to the edge point, on the neighbour.
            const glm::vec3 edgeP = evaluate(vase, {chart, 1.0f, along}).P;
            const ChartPoint beyond = adj.resolve(chart, 1.0f + 1e-3f, along);
            if (adj.link(chart, 1).chart < 0) continue;
            EXPECT_EQ(beyond.chart, adj.link(chart, 1).chart);
            const glm::vec3 p = evaluate(vase, beyond).P;
            EXPECT_LT(glm::length(p - edgeP), 1e-2f * scale);
            EXPECT_GT(glm::length(p - edgeP), 1e-6f * scale);
            // And the step continues the direction the chart was going.
            const glm::vec3 inside = evaluate(vase, {chart, 1.0f - 1e-3f, along}).P;
            EXPECT_GT(glm::dot(p - edgeP, edgeP - inside), 0.0f);
        }
    }
}

}  // namespace
}  // namespace mpshade
