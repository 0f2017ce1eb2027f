// Per-pixel shading cost: the points of each shading rate where one surface covers the
// image, shared among the pixels that composite them, and an edge between two objects.
#include "phases/shading_cost_image.h"

#include <gtest/gtest.h>

namespace mpshade {
namespace {

// A width x height image, 4 samples a pixel, one layer: object 0 left of column `split`,
// object 1 from there on, both at depth 1 on facet 0.
VisibilityBuffer twoObjects(int width, int height, int split) {
    VisibilityBuffer vis;
    vis.resize(width, height, 4, 1);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            for (int k = 0; k < 4; ++k) {
                const size_t s = (static_cast<size_t>(y) * width + x) * 4 + k;
                vis.count[s] = 1;
                vis.invDepth[s] = 1.0f;
                vis.object[s] = x < split ? 0u : 1u;
                vis.facet[s] = 0;
            }
    return vis;
}

TEST(ShadingCostImage, EachRateSharesItsPointsAmongThePixelsThatUseThem) {
    const SampleLayout layout(8, 4, 4, 7u);
    const VisibilityBuffer vis = twoObjects(8, 4, 4);  // the split on a 2x2 block's edge
    const float costs[] = {3.0f, 10.0f};
    struct Case {
        ShadingRate rate;
        float pointsPerPixel;
    };
    for (const Case c : {Case{ShadingRate::Sample, 4.0f}, Case{ShadingRate::Pixel, 1.0f},
                         Case{ShadingRate::Quad, 0.25f}}) {
        for (const bool shortcut : {true, false}) {
            const ShadingCostImage img = shadingCostImage(layout, vis, {c.rate, shortcut}, costs);
            ASSERT_EQ(img.width, 8);
            ASSERT_EQ(img.height, 4);
            for (int y = 0; y < 4; ++y)
                for (int x = 0; x < 8; ++x) {
                    const size_t p = static_cast<size_t>(y) * 8 + x;
                    EXPECT_FLOAT_EQ(img.points[p], c.pointsPerPixel) << x << "," << y;
                    EXPECT_FLOAT_EQ(img.cost[p], c.pointsPerPixel * (x < 4 ? 3.0f : 10.0f))
                        << x << "," << y;
                }
            EXPECT_DOUBLE_EQ(img.objectPoints[0], 16.0 * c.pointsPerPixel);
            EXPECT_DOUBLE_EQ(img.totalCost(), 16.0 * c.pointsPerPixel * 13.0);
        }
    }
}

TEST(ShadingCostImage, ABlockTwoObjectsShareHasAPointOfEach) {
    // The split through the middle of 2x2 blocks (column 3): per block each object's samples
    // make one point, shared by the block's two pixels on its side.
    const SampleLayout layout(8, 4, 4, 7u);
    const VisibilityBuffer vis = twoObjects(8, 4, 3);
    const float costs[] = {3.0f, 10.0f};
    const ShadingCostImage img = shadingCostImage(layout, vis, {ShadingRate::Quad, true}, costs);
    EXPECT_FLOAT_EQ(img.points[2], 0.5f);  // (2, 0): the block's left column, object 0
    EXPECT_FLOAT_EQ(img.points[3], 0.5f);  // (3, 0): its right column, object 1
    EXPECT_FLOAT_EQ(img.cost[3], 5.0f);
    EXPECT_FLOAT_EQ(img.points[0], 0.25f);  // a block one object covers
    // 4 blocks across x 2 down, and a second point in each of the 2 blocks split.
    EXPECT_DOUBLE_EQ(img.totalPoints(), 10.0);
}

TEST(ShadingCostImage, ABufferOfAnotherSizeGivesNothing) {
    const SampleLayout layout(8, 4, 4, 7u);
    const VisibilityBuffer vis = twoObjects(4, 4, 2);
    EXPECT_EQ(shadingCostImage(layout, vis, {}, {}).width, 0);
}

}  // namespace
}  // namespace mpshade
