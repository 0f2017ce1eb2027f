// Prefetching (patent claims 10 and 11): a tile prefetched before the frame that reads it
// is not missing there and counts as used; one no frame reads counts as wasted; the
// low-resolution prediction names the tiles the full frame will find missing.
#include <algorithm>
#include <chrono>

#include <gtest/gtest.h>

#include "controller/multiphase_renderer.h"
#include "controller/tile_predictor.h"
#include "test_support.h"

namespace mpshade {
namespace {

MultiphaseOptions budgeted() {
    MultiphaseOptions o;
    o.staticPhase.shaderMap.fillPinnedUpFront = true;
    o.singlePhaseFrames = false;
    o.frameBudgetSeconds = 60.0;  // time for everything: no test here depends on a clock
    return o;
}

RenderOptions small() {
    RenderOptions r;
    r.width = 96;
    r.height = 54;
    return r;
}

// How many tiles frame `frame` finds missing after frame 0, nothing prefetched.
uint64_t tilesMissing(const Scene& scene, int frame) {
    MultiphaseRenderer renderer(scene, budgeted());
    FrameStats stats;
    renderer.renderFrame(0, small(), stats);
    renderer.renderFrame(frame, small(), stats);
    return stats.tiles.missing;
}

TEST(TilePrefetch, PrefetchedTilesAreNotMissingAndCountAsUsed) {
    const Scene scene = loadScene(test::sourcePath("examples/vase/scene.json"));
    // Frame 16 after frame 0: the camera has orbited 30 degrees.
    const uint64_t missingWithout = tilesMissing(scene, 16);
    ASSERT_GT(missingWithout, 20u);
    // Predicted at the full size, and at half of it (footprints scaled to match the full
    // image's: a planted "no scaling" reads a level too coarse and fails here).
    for (int divisor : {1, 2}) {
        MultiphaseRenderer renderer(scene, budgeted());
        FrameStats stats;
        renderer.renderFrame(0, small(), stats);
        double seconds = 0.0;
        const std::vector<TileRequest> predicted =
            TilePredictor(renderer).predict(16, small(), divisor, seconds);
        ASSERT_FALSE(predicted.empty());
        for (const TileRequest& r : predicted)
            ASSERT_FALSE(renderer.representation(r.object)->map->resident(r.key));
        FrameStats slack;
        renderer.prefetch(predicted, 60.0, slack);
        EXPECT_EQ(slack.prefetch.filled, predicted.size());
        FrameStats ahead;
        renderer.renderFrame(16, small(), ahead);
        RecordProperty(
            "missing_after_prediction_" + std::to_string(divisor),
            std::to_string(ahead.tiles.missing) + " of " + std::to_string(missingWithout));
        // The frame shades per sample at 4 samples: the same footprint as the prediction's
        // per-pixel points (half a pixel), so little of what was predicted is missing.
        EXPECT_LT(ahead.tiles.missing * (divisor == 1 ? 4 : 2), missingWithout) << divisor;
        EXPECT_GT(ahead.prefetch.used, slack.prefetch.filled / 2) << divisor;
        EXPECT_LE(ahead.prefetch.used, slack.prefetch.filled);
        EXPECT_EQ(ahead.prefetch.wasted, 0u);
    }
}

TEST(TilePrefetch, ATileNoFrameReadsIsWastedAfterThePatience) {
    const Scene scene = loadScene(test::sourcePath("examples/vase/scene.json"));
    MultiphaseOptions o = budgeted();
    o.prefetchPatienceFrames = 3;
    MultiphaseRenderer renderer(scene, o);
    FrameStats stats;
    renderer.renderFrame(0, small(), stats);
    // The finest level's corner tile of the vase's first chart: no 96x54 frame reads it.
    const size_t vase = scene.objects[0].name == "vase" ? 0 : 1;
    const ShaderMap& map = *renderer.representation(vase)->map;
    const TileKey corner{0, 0, static_cast<uint16_t>(map.tilesU(0, 0) - 1),
                         static_cast<uint16_t>(map.tilesV(0, 0) - 1)};
    const TileRequest unread{static_cast<uint32_t>(vase), corner};
    FrameStats slack;
    renderer.prefetch(std::span<const TileRequest>(&unread, 1), 60.0, slack);
    ASSERT_EQ(slack.prefetch.filled, 1u);
    uint64_t wasted = 0, used = 0;
    for (int f = 1; f <= 3; ++f) {
        renderer.renderFrame(f, small(), stats);
        wasted += stats.prefetch.wasted;
        used += stats.prefetch.used;
        EXPECT_EQ(stats.prefetch.wasted, f == 3 ? 1u : 0u) << f;
    }
    EXPECT_EQ(used, 0u);
    EXPECT_EQ(wasted, 1u);
    EXPECT_TRUE(map.resident(corner));  // still an ordinary tile of the cache
}

TEST(TilePrefetch, AGuessNeverDisplacesATileInTheCache) {
    const Scene scene = loadScene(test::sourcePath("examples/vase/scene.json"));
    // A cache exactly as large as what frames 0 and 8 leave resident: full, nothing evicted.
    uint64_t full = 0;
    {
        MultiphaseRenderer roomy(scene, budgeted());
        FrameStats stats;
        roomy.renderFrame(0, small(), stats);
        roomy.renderFrame(8, small(), stats);
        full = stats.tiles.residentBytes;
    }
    MultiphaseOptions o = budgeted();
    o.mapMemoryBytes = full;
    MultiphaseRenderer renderer(scene, o);
    FrameStats stats;
    renderer.renderFrame(0, small(), stats);
    renderer.renderFrame(8, small(), stats);  // frame 0's tiles it does not read: evictable
    ASSERT_EQ(stats.tiles.evicted, 0u);
    ASSERT_EQ(stats.tiles.residentBytes, full);
    double seconds = 0.0;
    const std::vector<TileRequest> predicted =
        TilePredictor(renderer).predict(16, small(), 1, seconds);
    ASSERT_FALSE(predicted.empty());
    FrameStats slack;
    renderer.prefetch(predicted, 60.0, slack);
    // A frame's demand would evict frame 0's tiles to fit (planting that fails here); a
    // guess finds no room and fills nothing.
    EXPECT_EQ(slack.tiles.evicted, 0u);
    EXPECT_EQ(slack.prefetch.filled, 0u);
}

TEST(TilePrefetch, PredictionPastItsDeadlineIsAbandoned) {
    // `play` gives a prediction only the frame's slack: past its deadline it names no tile
    // and says it was abandoned, and the cost it held stands (a planted "seconds = time
    // spent" would make the next frame start one it has no time for). The next prediction,
    // with time, is whole again.
    const Scene scene = loadScene(test::sourcePath("examples/vase/scene.json"));
    MultiphaseRenderer renderer(scene, budgeted());
    FrameStats stats;
    renderer.renderFrame(0, small(), stats);
    TilePredictor predictor(renderer);
    double seconds = 5.0;
    const std::vector<TileRequest> late = predictor.predict(
        16, small(), 1, seconds, std::chrono::steady_clock::now() - std::chrono::seconds(1));
    EXPECT_TRUE(late.empty());
    EXPECT_TRUE(predictor.abandoned());
    EXPECT_EQ(seconds, 5.0);
    const std::vector<TileRequest> whole = predictor.predict(
        16, small(), 1, seconds, std::chrono::steady_clock::now() + std::chrono::hours(1));
    EXPECT_FALSE(predictor.abandoned());
    EXPECT_FALSE(whole.empty());
    EXPECT_LT(seconds, 5.0);
    double untimedSeconds = 0.0;
    EXPECT_EQ(predictor.predict(16, small(), 1, untimedSeconds).size(), whole.size());
}

TEST(TilePrefetch, NeighboursOfMissingTilesAreAdjacentAndNotResident) {
    const Scene scene = loadScene(test::sourcePath("examples/vase/scene.json"));
    MultiphaseRenderer renderer(scene, budgeted());
    FrameStats stats;
    renderer.renderFrame(0, small(), stats);
    renderer.renderFrame(1, small(), stats);
    ASSERT_GT(stats.tiles.missing, 0u);
    const std::vector<TileRequest> adjacent = renderer.adjacentTiles();
    ASSERT_FALSE(adjacent.empty());
    for (const TileRequest& r : adjacent) {
        const ShaderMap& map = *renderer.representation(r.object)->map;
        EXPECT_FALSE(map.resident(r.key));
        EXPECT_LT(r.key.tx, map.tilesU(r.key.chart, r.key.level));
        EXPECT_LT(r.key.ty, map.tilesV(r.key.chart, r.key.level));
    }
    for (size_t k = 1; k < adjacent.size(); ++k)
        EXPECT_FALSE(adjacent[k].object == adjacent[k - 1].object &&
                     adjacent[k].key == adjacent[k - 1].key);
}

}  // namespace
}  // namespace mpshade
