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

// Per pixel or per 2x2 block, what the points must be, worked out here from the definition
// (band_points.h): a block's fragments grouped by object and layer in the order met (row,
// column, sample, layer), each group's point at its centroid on the facet of its member
// nearest to it (the first such), the points grouped by object in the order the blocks and
// groups were met. Per fragment, the point it composites.
struct ExpectedBlocks {
    std::vector<Expected> points;         // in their final order; slot unused
    std::vector<uint32_t> fragmentPoint;  // per slot of the range's rows
    std::vector<uint8_t> wholeBlock;      // per pixel of the range's rows: its block is whole
};

ExpectedBlocks expectedBlockPoints(const SampleLayout& layout, const VisibilityBuffer& vis,
                                   const BandRange& r, uint32_t objects, int block) {
    struct Group {
        uint32_t object;
        int layer;
        float fx = 0, fy = 0;  // sums in the order met
        int count = 0;
        std::vector<size_t> slots;
    };
    const size_t layers = static_cast<size_t>(vis.layers);
    const size_t width = static_cast<size_t>(layout.width());
    std::vector<Group> made;  // every block's groups, in the order met
    std::vector<size_t> slotGroup((r.endSample - r.firstSample) * layers, ~size_t{0});
    ExpectedBlocks e;
    e.wholeBlock.assign(static_cast<size_t>(r.row1 - r.row0) * width, 0);
    for (int by = r.row0; by < r.row1; by += block)
        for (int bx = r.col0; bx < r.col1; bx += block) {
            const size_t first = made.size();
            bool whole = true;
            int samples = 0;
            for (int py = by; py < std::min(r.row1, by + block); ++py)
                for (int px = bx; px < std::min(r.col1, bx + block); ++px)
                    for (int k = 0; k < layout.spp(); ++k) {
                        const size_t smp = layout.index(px, py, k);
                        ++samples;
                        whole = whole && vis.count[smp] == 1;
                        for (int l = 0; l < vis.count[smp]; ++l) {
                            const size_t slot = smp * layers + static_cast<size_t>(l);
                            size_t g = first;
                            while (g < made.size() &&
                                   !(made[g].object == vis.object[slot] && made[g].layer == l))
                                ++g;
                            if (g == made.size())
                                made.push_back({vis.object[slot], l, 0.0f, 0.0f, 0, {}});
                            made[g].fx += layout.x(smp);
                            made[g].fy += layout.y(smp);
                            ++made[g].count;
                            made[g].slots.push_back(slot);
                            slotGroup[slot - r.firstSlot] = g;
                        }
                    }
            whole = whole && made.size() == first + 1 && samples == block * block * layout.spp();
            for (int py = by; py < std::min(r.row1, by + block); ++py)
                for (int px = bx; px < std::min(r.col1, bx + block); ++px)
                    e.wholeBlock[static_cast<size_t>(py - r.row0) * width + px] = whole;
        }
    std::vector<uint32_t> pointOf(made.size());
    for (uint32_t o = 0; o < objects; ++o)
        for (size_t g = 0; g < made.size(); ++g) {
            if (made[g].object != o) continue;
            const float cx = made[g].fx / made[g].count, cy = made[g].fy / made[g].count;
            float best = 1e30f;
            uint32_t facet = 0;
            for (const size_t slot : made[g].slots) {
                const size_t smp = slot / layers;
                const float dx = layout.x(smp) - cx, dy = layout.y(smp) - cy;
                if (dx * dx + dy * dy < best) best = dx * dx + dy * dy, facet = vis.facet[slot];
            }
            pointOf[g] = static_cast<uint32_t>(e.points.size());
            e.points.push_back({o, facet, cx, cy, 0});
        }
    e.fragmentPoint.assign(slotGroup.size(), kNoPoint);
    for (size_t s = 0; s < slotGroup.size(); ++s)
        if (slotGroup[s] != ~size_t{0}) e.fragmentPoint[s] = pointOf[slotGroup[s]];
    return e;
}

// Mostly one fragment a sample, in runs of one object or of nothing (the background), so
// that whole and empty pixels and blocks are common; now and then an empty sample or a
// second layer.
VisibilityBuffer mostlyWholeVisibility(const SampleLayout& layout, int layers, uint32_t objects,
                                       std::mt19937& random) {
    VisibilityBuffer vis;
    vis.resize(layout.width(), layout.height(), layout.spp(), layers);
    std::uniform_int_distribution<uint32_t> pickObject(0, objects - 1), run(1, 60), odd(0, 19);
    uint32_t object = 0, left = 0;
    bool background = false;
    for (size_t smp = 0; smp < layout.count(); ++smp) {
        if (left == 0) {
            object = pickObject(random), left = run(random) * layout.spp();
            background = odd(random) < 6;
        }
        --left;
        const uint32_t roll = odd(random);
        vis.count[smp] = background || roll == 0 ? 0 : (roll == 1 && layers > 1 ? 2 : 1);
        for (int l = 0; l < layers; ++l) {
            const size_t slot = smp * static_cast<size_t>(layers) + l;
            vis.object[slot] = l == 0 ? object : pickObject(random);
            vis.facet[slot] = static_cast<uint32_t>(random() % 1000);
        }
    }
    return vis;
}

void expectBlockPoints(const SampleLayout& layout, const VisibilityBuffer& vis, const BandRange& r,
                       uint32_t objects, int block, bool shortcut, const BandPoints& pts) {
    const ExpectedBlocks e = expectedBlockPoints(layout, vis, r, objects, block);
    ASSERT_EQ(pts.object.size(), e.points.size());
    ASSERT_EQ(pts.objectStart.size(), objects + 1u);
    for (size_t p = 0; p < e.points.size(); ++p) {
        ASSERT_EQ(pts.object[p], e.points[p].object) << "point " << p;
        EXPECT_EQ(pts.facet[p], e.points[p].facet) << "point " << p;
        EXPECT_EQ(pts.x[p], e.points[p].x) << "point " << p;
        EXPECT_EQ(pts.y[p], e.points[p].y) << "point " << p;
        EXPECT_GE(p, pts.objectStart[e.points[p].object]);
        EXPECT_LT(p, pts.objectStart[e.points[p].object + 1]);
    }
    const size_t width = static_cast<size_t>(layout.width());
    const size_t layers = static_cast<size_t>(vis.layers);
    ASSERT_EQ(pts.pixelPoint.size(), static_cast<size_t>(r.row1 - r.row0) * width);
    for (int py = r.row0; py < r.row1; ++py)
        for (int px = r.col0; px < r.col1; ++px) {
            const size_t pixel = static_cast<size_t>(py - r.row0) * width + px;
            const uint32_t own = pts.pixelPoint[pixel];
            // A whole pixel, or a whole 2x2 block at even coordinates, takes the shortcut:
            // its pixels hold the point.
            const int bx = r.col0 + (px - r.col0) / block * block,
                      by = r.row0 + (py - r.row0) / block * block;
            const bool shortcutApplies =
                block == 1 || (bx % 2 == 0 && by % 2 == 0 && bx + 2 <= r.col1 && by + 2 <= r.row1);
            if (shortcut && e.wholeBlock[pixel] && shortcutApplies) {
                EXPECT_NE(own, kNoPoint) << "pixel " << px << "," << py;
            }
            if (!shortcut) {
                EXPECT_EQ(own, kNoPoint) << "pixel " << px << "," << py;
            }
            for (int k = 0; k < layout.spp(); ++k) {
                const size_t smp = layout.index(px, py, k);
                for (int l = 0; l < vis.count[smp]; ++l) {
                    const size_t slot = smp * layers + static_cast<size_t>(l) - r.firstSlot;
                    const uint32_t got = own != kNoPoint ? own : pts.fragmentPoint[slot];
                    EXPECT_EQ(got, e.fragmentPoint[slot])
                        << "pixel " << px << "," << py << " sample " << k << " layer " << l;
                }
            }
        }
    EXPECT_TRUE(pts.fresh);
    EXPECT_GE(pts.color.size(), 3 * e.points.size() + 1);
}

TEST(BandPoints, PerPixelOrBlockOnePointPerSurfaceAtItsCentroidGroupedByObject) {
    std::mt19937 random(8);
    for (const int layers : {1, 3})
        for (const int spp : {1, 4})
            for (const uint32_t objects : {1u, 3u})
                for (const int block : {1, 2})
                    for (const bool shortcut : {true, false}) {
                        SCOPED_TRACE(testing::Message()
                                     << layers << " layers, " << spp << " spp, " << objects
                                     << " objects, block " << block << ", shortcut " << shortcut);
                        const SampleLayout layout(29, 13, spp, 11u);
                        const VisibilityBuffer vis =
                            mostlyWholeVisibility(layout, layers, objects, random);
                        const BandPointOptions options{
                            block == 1 ? ShadingRate::Pixel : ShadingRate::Quad, shortcut};
                        BandPoints pts;
                        BandPointScratch scratch;
                        // Whole-row bands (odd heights: a last row of half blocks), reused.
                        for (const auto& [row0, row1] :
                             {std::pair{0, 4}, std::pair{4, 9}, std::pair{9, 13}}) {
                            const BandRange range(layout, layers, row0, row1);
                            buildBandPoints(layout, vis, range, objects, BandPointOptions{}, pts,
                                            scratch);
                            buildBandPoints(layout, vis, range, objects, options, pts, scratch);
                            expectBlockPoints(layout, vis, range, objects, block, shortcut, pts);
                        }
                        // Refined image tiles, one at odd columns (no block there is aligned).
                        for (const auto& [c0, c1] : {std::pair{4, 18}, std::pair{5, 17}}) {
                            const BandRange tile(layout, layers, 2, 8, c0, c1);
                            buildBandPoints(layout, vis, tile, objects, options, pts, scratch);
                            expectBlockPoints(layout, vis, tile, objects, block, shortcut, pts);
                        }
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
