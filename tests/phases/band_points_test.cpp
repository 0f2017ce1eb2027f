// A band's shading points per sample (phases/band_points.h) against what they must be,
// worked out here sample by sample: one point per fragment, grouped by object, in sample
// order within an object, each fragment pointing at its own point. One layer (every object
// opaque, the path that keeps its counts in registers) and several.
#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "phases/band_points.h"
#include "phases/sample_pattern.h"

namespace mpshade {
namespace {

struct Expected {
    uint32_t object, facet;
    float x, y;
    size_t slot;
};

// The fragments of rows [row0, row1), columns [col0, col1), in the order the points of
// each object must come: by object, then by sample, then by layer.
std::vector<Expected> expectedPoints(const SampleLayout& layout, const VisibilityBuffer& vis,
                                     const BandRange& r, uint32_t objects) {
    std::vector<Expected> points;
    for (uint32_t o = 0; o < objects; ++o)
        for (int py = r.row0; py < r.row1; ++py)
            for (int px = r.col0; px < r.col1; ++px)
                for (int k = 0; k < layout.spp(); ++k) {
                    const size_t smp = layout.index(px, py, k);
                    for (int l = 0; l < vis.count[smp]; ++l) {
                        const size_t slot = smp * static_cast<size_t>(vis.layers) + l;
                        if (vis.object[slot] == o)
                            points.push_back(
                                {o, vis.facet[slot], layout.x(smp), layout.y(smp), slot});
                    }
                }
    return points;
}

// Runs of one object of random lengths (as facets of an object cover runs of samples),
// empty samples among them; up to `layers` fragments a sample.
VisibilityBuffer randomVisibility(const SampleLayout& layout, int layers, uint32_t objects,
                                  std::mt19937& random) {
    VisibilityBuffer vis;
    vis.resize(layout.width(), layout.height(), layout.spp(), layers);
    std::uniform_int_distribution<uint32_t> pickObject(0, objects - 1), run(1, 40);
    std::uniform_int_distribution<int> fragments(0, layers);
    uint32_t object = 0, left = 0;
    for (size_t smp = 0; smp < layout.count(); ++smp) {
        if (left == 0) object = pickObject(random), left = run(random);
        --left;
        vis.count[smp] = static_cast<uint8_t>(fragments(random));
        for (int l = 0; l < layers; ++l) {
            const size_t slot = smp * static_cast<size_t>(layers) + l;
            // Later layers of a sample may be other objects (what is seen through).
            vis.object[slot] = l == 0 ? object : pickObject(random);
            vis.facet[slot] = static_cast<uint32_t>(random() % 1000);
        }
    }
    return vis;
}

void expectPoints(const SampleLayout& layout, const VisibilityBuffer& vis, const BandRange& r,
                  uint32_t objects, const BandPoints& pts) {
    const std::vector<Expected> expected = expectedPoints(layout, vis, r, objects);
    ASSERT_EQ(pts.object.size(), expected.size());
    ASSERT_EQ(pts.objectStart.size(), objects + 1u);
    EXPECT_EQ(pts.objectStart[0], 0u);
    for (size_t p = 0; p < expected.size(); ++p) {
        const Expected& e = expected[p];
        ASSERT_EQ(pts.object[p], e.object) << "point " << p;
        EXPECT_EQ(pts.facet[p], e.facet) << "point " << p;
        EXPECT_EQ(pts.x[p], e.x) << "point " << p;
        EXPECT_EQ(pts.y[p], e.y) << "point " << p;
        EXPECT_EQ(pts.fragmentPoint[e.slot - r.firstSlot], p) << "slot " << e.slot;
        EXPECT_GE(p, pts.objectStart[e.object]);
        EXPECT_LT(p, pts.objectStart[e.object + 1]);
    }
    EXPECT_TRUE(pts.pixelPoint.empty()) << "per sample, no pixel has a point of its own";
    EXPECT_TRUE(pts.fresh);
    EXPECT_TRUE(pts.built);
    EXPECT_GE(pts.color.size(), 3 * expected.size() + 1);
}

TEST(BandPoints, PerSampleEveryFragmentIsAPointGroupedByObjectInSampleOrder) {
    std::mt19937 random(5);
    for (const int layers : {1, 3})
        for (const int spp : {1, 4})
            for (const uint32_t objects : {1u, 2u, 7u}) {
                SCOPED_TRACE(testing::Message()
                             << layers << " layers, " << spp << " spp, " << objects << " objects");
                const SampleLayout layout(29, 13, spp, 11u);
                const VisibilityBuffer vis = randomVisibility(layout, layers, objects, random);
                BandPoints pts;
                BandPointScratch scratch;
                // Bands of whole rows, the first, a middle one and the last, the same arrays
                // reused from band to band as a thread does.
                for (const auto& [row0, row1] :
                     {std::pair{0, 4}, std::pair{4, 9}, std::pair{9, 13}}) {
                    const BandRange range(layout, layers, row0, row1);
                    // Arrays a per-pixel band left behind, as refinement's passes do.
                    buildBandPoints(layout, vis, range, objects, {ShadingRate::Pixel, true}, pts,
                                    scratch);
                    buildBandPoints(layout, vis, range, objects, BandPointOptions{}, pts, scratch);
                    expectPoints(layout, vis, range, objects, pts);
                }
                // A refined image tile's columns.
                const BandRange tile(layout, layers, 2, 8, 5, 17);
                buildBandPoints(layout, vis, tile, objects, BandPointOptions{}, pts, scratch);
                expectPoints(layout, vis, tile, objects, pts);
            }
}

// A frame that draws no object: no points, and nothing written outside the arrays (ASan).
TEST(BandPoints, NoObjectsNoPoints) {
    for (const int layers : {1, 2}) {
        const SampleLayout layout(9, 5, 4, 1u);
        VisibilityBuffer vis;
        vis.resize(9, 5, 4, layers);
        std::fill(vis.count.begin(), vis.count.end(), uint8_t{0});
        BandPoints pts;
        BandPointScratch scratch;
        const BandRange range(layout, layers, 0, 5);
        buildBandPoints(layout, vis, range, 0, BandPointOptions{}, pts, scratch);
        EXPECT_TRUE(pts.object.empty());
        ASSERT_EQ(pts.objectStart.size(), 1u);
        EXPECT_EQ(pts.objectStart[0], 0u);
    }
}

}  // namespace
}  // namespace mpshade
