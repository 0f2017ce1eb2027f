// What a scene's frames ask of a shader map (map_demand.h), against numbers worked out by
// hand: a square facing the camera is an affine image of its chart, so every probe's
// footprint is the same and its level follows from the distance alone.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "phases/map_demand.h"
#include "scene/scene.h"
#include "test_support.h"

namespace mpshade {
namespace {

// A 2 x 2 square turned to face a camera on +z at distance `distance` (fov_y 90 degrees,
// 640 x 480: 240 pixels a unit of height at distance 1), 4 samples a pixel (footprint 1/2
// pixel). The chart spans 2 * 240 / distance pixels, so a pixel step is distance / 480 of
// it, and the probe's footprint 2^20 * distance / 960 level-0 texels: level log2 of that.
// `occluder`: a second square in front hiding x < 0 of the first, as the eye sees it.
Scene squareScene(const std::string& name, double lod, bool occluder,
                  const std::string& size = "[2, 2]") {
    const double distance = std::exp2(lod) * 960.0 / double(1 << 20);
    const std::string dir = test::testFolder("mpshade_map_demand");
    std::ofstream(dir + "s.sl") << "surface s() { Ci = color(noise(P * 40)); }";
    std::string objects = R"({"name": "square", "geometry": {"type": "plane", "size": )" + size +
                          R"(}, "shader": "s", "transform": {"rotate": [1, 0, 0, 90]}})";
    if (occluder)
        // Half as far from the eye as the square, so it hides x in [-1, 0] there if it
        // spans x in [-0.5, 0] (and all of y) at its own depth.
        objects += R"(, {"name": "occluder", "geometry": {"type": "plane", "size": [1, 4]},
            "shader": "s", "transform": {"rotate": [1, 0, 0, 90], "translate": [-0.5, 0, )" +
                   std::to_string(0.5 * distance) + "]}}";
    std::ofstream(dir + name) << R"({"settings": {"width": 640, "height": 480, "fps": 10,
      "duration": 0.1, "samples_per_pixel": 4},
      "camera": {"fov_y": 90, "near": 0.001, "eye": [0, 0, )"
                              << distance << R"(], "target": [0, 0, 0]},
      "shaders": {"s": "s.sl"}, "objects": [)"
                              << objects << "]}";
    return loadScene(dir + name);
}

MapDemand demandOf(const Scene& scene) {
    const SceneResources resources(scene, SceneResources::RayScenes::All);
    const size_t square = 0;
    return estimateMapDemands(resources, std::span<const size_t>(&square, 1))[0];
}

TEST(MapDemand, ASquareFacingTheCameraAsksForTheLevelItsFootprintMatches) {
    // lod 10.25: level 10 only, 1024 texels a side, 64 x 64 tiles of 16.
    const MapDemand d = demandOf(squareScene("a.json", 10.25, false));
    EXPECT_EQ(d.resolution, 1 << 20);
    EXPECT_EQ(d.frame, 0);
    EXPECT_EQ(d.finestLevel, 10);
    EXPECT_DOUBLE_EQ(d.tiles, 64.0 * 64.0);
    const double side = 524288.0 / std::exp2(10.25);  // 2 * 240 / distance pixels
    EXPECT_NEAR(d.coveredPixels, side * side, 1e-3 * side * side);
    EXPECT_EQ(d.tileTexels, 18 * 18);
    EXPECT_DOUBLE_EQ(d.bytes(3, false), 4096.0 * 18 * 18 * 3 * 4);
    EXPECT_DOUBLE_EQ(d.bytes(3, true), 4096.0 * 18 * 18 * 3 * 2);
    EXPECT_DOUBLE_EQ(d.pinnedTiles, 9.0);
}

TEST(MapDemand, AStretchedRectangleAsksForSquareTexels) {
    // 2 x 0.5: v spans a quarter of u's length, so its chart has a quarter of the texels
    // along v (chart_aspect.h): 2^18 a side at level 0, where a sample's step is a quarter of
    // the chart's v instead of u's -- the same 2^20 * distance / 960 texels both ways, level
    // 10: 64 x 16 tiles. The always-resident levels: 32 x 8 texels is two tiles, the five
    // below one each. Square texels (chartAspect off): the level of u, 64 x 64 tiles.
    const Scene scene = squareScene("g.json", 10.25, false, "[2, 0.5]");
    const MapDemand d = demandOf(scene);
    EXPECT_EQ(d.finestLevel, 10);
    EXPECT_DOUBLE_EQ(d.tiles, 64.0 * 16.0);
    EXPECT_DOUBLE_EQ(d.pinnedTiles, 7.0);
    const SceneResources resources(scene, SceneResources::RayScenes::All);
    const size_t square = 0;
    MapDemandOptions squareTexels;
    squareTexels.chartAspect = false;
    const MapDemand s =
        estimateMapDemands(resources, std::span<const size_t>(&square, 1), squareTexels)[0];
    EXPECT_DOUBLE_EQ(s.tiles, 64.0 * 64.0);
    EXPECT_DOUBLE_EQ(s.pinnedTiles, 9.0);
}

TEST(MapDemand, LevelsAreReadWhereTheirBlendWeightIsNotZero) {
    // The renderer's probe blends two levels only within 1/16 of the middle
    // (ProbeOptions::levelBlend 0.125, lod fractions 0.4375 to 0.5625): at lod 10.6 level
    // 11 alone (32 x 32 tiles), at 10.45 and 10.55 both levels, at 10.4 level 10 alone.
    EXPECT_DOUBLE_EQ(demandOf(squareScene("b.json", 10.6, false)).tiles, 32.0 * 32.0);
    EXPECT_DOUBLE_EQ(demandOf(squareScene("c.json", 10.45, false)).tiles, 64.0 * 64 + 32 * 32);
    EXPECT_DOUBLE_EQ(demandOf(squareScene("f.json", 10.55, false)).tiles, 64.0 * 64 + 32 * 32);
    EXPECT_DOUBLE_EQ(demandOf(squareScene("d.json", 10.4, false)).tiles, 64.0 * 64.0);
}

TEST(MapDemand, WhatIsHiddenAsksForNothing) {
    // The occluder hides the half x < 0 of the square: tile columns 0-31 of 64.
    const MapDemand d = demandOf(squareScene("e.json", 10.25, true));
    EXPECT_DOUBLE_EQ(d.tiles, 32.0 * 64.0);
    const double side = 524288.0 / std::exp2(10.25);
    EXPECT_NEAR(d.coveredPixels, 0.5 * side * side, 0.01 * side * side);
}

TEST(MapDemand, AFloorSeenFromCloseByAtAGrazingAngleCoversHalfTheImage) {
    // A 1000 x 1000 floor, the eye 0.2 above it looking level (fov_y 90, 640 x 480): every
    // pixel below the horizon, the image's lower half, sees it (the floor's far edge is
    // 1/20 of a pixel under the horizon). Its near cells are hundreds of pixels wide and
    // straddle the image's edge, so they are split until each is a few pixels: counted by
    // their centres alone, the lower half came out a twelfth of itself.
    const std::string dir = test::testFolder("mpshade_map_demand");
    std::ofstream(dir + "s.sl") << "surface s() { Ci = color(noise(P * 40)); }";
    std::ofstream(dir + "floor.json") << R"({"settings": {"width": 640, "height": 480,
      "fps": 10, "duration": 0.1, "samples_per_pixel": 4},
      "camera": {"fov_y": 90, "near": 0.01, "far": 10000, "eye": [0, 0.2, 0],
                 "target": [0, 0.2, -10]},
      "shaders": {"s": "s.sl"},
      "objects": [{"name": "floor", "geometry": {"type": "plane", "size": [1000, 1000]},
                   "shader": "s"}]})";
    const MapDemand d = demandOf(loadScene(dir + "floor.json"));
    EXPECT_EQ(d.frame, 0);
    EXPECT_NEAR(d.coveredPixels, 640.0 * 240.0, 0.02 * 640.0 * 240.0);
    EXPECT_GT(d.tiles, 0.0);
    EXPECT_TRUE(std::isfinite(d.tiles));
}

}  // namespace
}  // namespace mpshade
