// A frame's stats.json entry (app/frame_stats_json.h): the pixels an image covers and the
// facets per covered pixel, against sums worked out here.
#include <gtest/gtest.h>

#include "app/frame_stats_json.h"
#include "test_support.h"

namespace mpshade {
namespace {

TEST(FrameStatsJson, CoveredPixelsAreTheSumOfTheImagesAlphas) {
    const Scene scene = loadScene(test::sourcePath("examples/vase/scene.json"));
    // 7 x 3 pixels: a count no multiple of four (the last pixel covered), alphas 0.25 apart
    // and some zero.
    Image image(7, 3);
    double expected = 0.0;
    for (int p = 0; p < 21; ++p) {
        const float a = static_cast<float>((p + 1) % 5) * 0.25f;
        image.rgba[4 * static_cast<size_t>(p) + 3] = a;
        image.rgba[4 * static_cast<size_t>(p)] = 9.0f;  // colours do not count
        expected += a;
    }
    ASSERT_EQ(expected, 10.25);  // 4 runs of 0.25..1 and 0 (2.5 each), then 0.25
    FrameStats stats;
    stats.dynamic.raster.facetsBinned = 41;
    const nlohmann::json entry = renderFrameJson(scene, stats, true, image);
    EXPECT_EQ(entry["covered_pixels"].get<double>(), 10.25);
    EXPECT_EQ(entry["facets_per_covered_pixel"].get<double>(), 4.0);
    // Nothing covered: no facets per pixel, not a division by zero.
    const nlohmann::json empty = renderFrameJson(scene, stats, true, Image(3, 2));
    EXPECT_EQ(empty["covered_pixels"].get<double>(), 0.0);
    EXPECT_EQ(empty["facets_per_covered_pixel"].get<double>(), 0.0);
}

}  // namespace
}  // namespace mpshade
