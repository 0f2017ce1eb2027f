// The one tile filler's limits: how each CacheRoom keeps the cache's budget (at the budget
// exactly and one byte under it), what it skips, and a deadline already past; and a
// budgeted frame's fill order and end.
#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <vector>

#include "controller/tile_filler.h"
#include "test_support.h"

namespace mpshade {
namespace {

// The vase scene's first object built as a shader map for frame 0 at 96 x 54, its
// always-resident levels filled; nothing else resident.
struct MapFixture {
    Scene scene = loadScene(test::sourcePath("examples/vase/scene.json"));
    SceneResources resources{scene, SceneResources::RayScenes::ForOcclusion};
    StaticPhase statics{scene, resources, pinnedUpFront()};
    std::unique_ptr<ObjectRepresentation> rep;
    std::vector<const ObjectRepresentation*> reps;
    MapFixture() {
        const FrameState frame = frameStateAt(resources, 0, 96, 54, 4);
        StaticCosts costs;
        rep = statics.build(0, Representation::ShaderMap, frame.objects[0], frame.camera,
                            frame.uniforms[0], nullptr, costs);
        reps.assign(scene.objects.size(), nullptr);
        reps[0] = rep.get();
    }
    static StaticPhaseOptions pinnedUpFront() {
        StaticPhaseOptions o;
        o.shaderMap.fillPinnedUpFront = true;
        return o;
    }
    ShaderMap& map() const { return *rep->map; }
    size_t held() const { return statics.tilePools().bytesHeld(); }
    // `count` tiles of the finest level of chart 0, along its first row from column `from`.
    std::vector<TileRequest> finest(int count, int from = 0) const {
        std::vector<TileRequest> out;
        for (int t = from; t < from + count; ++t)
            out.push_back({0, TileKey{0, 0, static_cast<uint16_t>(t), 0}});
        return out;
    }
};

FillLimits limits(CacheRoom room, uint32_t stamp = 1) {
    FillLimits l;
    l.room = room;
    l.useStamp = stamp;
    return l;
}

TEST(TileFiller, EachRoomPolicyFillsAtTheBudgetExactlyAndStopsOneByteUnder) {
    for (CacheRoom room : {CacheRoom::EvictWithin, CacheRoom::RoomLeft}) {
        for (size_t under : {size_t{0}, size_t{1}}) {
            MapFixture f;
            ASSERT_GE(f.map().tilesU(0, 0), 4);
            const std::vector<TileRequest> tiles = f.finest(3);
            TileCache cache(f.held() + 3 * f.map().tileBytes() - under);
            TileFiller filler(f.statics, cache);
            TileFillResult result;
            filler.fill(tiles, f.reps, limits(room), result);
            const uint64_t expected = under ? 0 : 3;
            EXPECT_EQ(result.costs.tilesFilled, expected) << static_cast<int>(room) << under;
            EXPECT_EQ(result.consumed, expected) << static_cast<int>(room) << under;
            EXPECT_EQ(result.filled.size(), expected);
            EXPECT_EQ(result.objectTiles[0], expected);
            EXPECT_EQ(f.map().resident(tiles[2].key), under == 0);
            EXPECT_EQ(result.evicted, 0u);  // nothing old enough to drop
        }
    }
}

TEST(TileFiller, ConstantQualityFillsBeyondTheBudget) {
    MapFixture f;
    TileCache cache(1);  // far below even the always-resident levels
    TileFiller filler(f.statics, cache);
    TileFillResult result;
    filler.fill(f.finest(4), f.reps, limits(CacheRoom::EvictAndExceed), result);
    EXPECT_EQ(result.costs.tilesFilled, 4u);
    EXPECT_EQ(result.consumed, 4u);
    EXPECT_GT(f.held(), cache.budgetBytes());
}

TEST(TileFiller, OnlyAFrameFillEvictsAndAGuessNeverDoes) {
    // Two tiles used at stamp 1; a fill at stamp 5 with room for one more tile only: the
    // evicting policies drop the old tiles and fill, room-left fills nothing and drops none.
    for (CacheRoom room :
         {CacheRoom::EvictWithin, CacheRoom::EvictAndExceed, CacheRoom::RoomLeft}) {
        MapFixture f;
        const std::vector<TileRequest> old = f.finest(2);
        f.map().setUseStamp(1);
        TileCache roomy(size_t{1} << 30);
        TileFillResult warm;
        TileFiller(f.statics, roomy).fill(old, f.reps, limits(CacheRoom::RoomLeft, 1), warm);
        ASSERT_TRUE(f.map().resident(old[1].key));
        f.map().setUseStamp(5);
        TileCache cache(f.held() + f.map().tileBytes());
        TileFiller filler(f.statics, cache);
        TileFillResult result;
        filler.fill(f.finest(3, 2), f.reps, limits(room, 5), result);
        const bool evicts = room != CacheRoom::RoomLeft;
        EXPECT_EQ(result.costs.tilesFilled, evicts ? 3u : 0u) << static_cast<int>(room);
        EXPECT_EQ(result.evicted, evicts ? 2u : 0u) << static_cast<int>(room);
        EXPECT_EQ(f.map().resident(old[0].key), !evicts) << static_cast<int>(room);
    }
}

TEST(TileFiller, SkipsResidentTilesAndObjectsWithoutAMap) {
    MapFixture f;
    TileCache cache(size_t{1} << 30);
    TileFiller filler(f.statics, cache);
    TileFillResult first;
    filler.fill(f.finest(1), f.reps, limits(CacheRoom::EvictWithin), first);
    ASSERT_EQ(first.costs.tilesFilled, 1u);
    // The resident tile again, a tile of an object with no representation, and a new one.
    std::vector<TileRequest> tiles = f.finest(2);
    tiles.insert(tiles.begin() + 1, TileRequest{1, TileKey{0, 0, 5, 0}});
    TileFillResult result;
    filler.fill(tiles, f.reps, limits(CacheRoom::EvictWithin), result);
    EXPECT_EQ(result.consumed, 3u);
    EXPECT_EQ(result.costs.tilesFilled, 1u);
    ASSERT_EQ(result.filled.size(), 1u);
    EXPECT_EQ(result.filled[0].key, tiles[2].key);
}

TEST(TileFiller, ADeadlineAlreadyPastFillsNothing) {
    MapFixture f;
    TileCache cache(size_t{1} << 30);
    TileFiller filler(f.statics, cache);
    FillLimits l = limits(CacheRoom::EvictWithin);
    l.deadline = std::chrono::steady_clock::now() - std::chrono::milliseconds(1);
    TileFillResult result;
    filler.fill(f.finest(3), f.reps, l, result);
    EXPECT_EQ(result.consumed, 0u);
    EXPECT_EQ(result.costs.tilesFilled, 0u);
    EXPECT_FALSE(f.map().resident(f.finest(1)[0].key));
}

TEST(TileFiller, AChunkStillRunningAtTheDeadlineStopsAndLeavesItsTiles) {
    MapFixture f;
    TileCache cache(size_t{1} << 30);
    const int side = std::min(f.map().tilesU(0, 0), f.map().tilesV(0, 0));
    ASSERT_GE(side, 8);
    // Deadlines ever further off until one lands inside a chunk (a vase tile is a
    // millisecond or so of occlusion rays; the first chunk is two tiles, unmeasured).
    bool seen = false;
    for (int attempt = 0; attempt < side && !seen; ++attempt) {
        TileFiller filler(f.statics, cache);
        std::vector<TileRequest> row;
        for (int t = 0; t < side; ++t)
            row.push_back(
                {0, TileKey{0, 0, static_cast<uint16_t>(t), static_cast<uint16_t>(attempt)}});
        FillLimits l = limits(CacheRoom::EvictWithin);
        l.deadline = std::chrono::steady_clock::now() + std::chrono::microseconds(100 << attempt);
        TileFillResult result;
        filler.fill(row, f.reps, l, result);
        if (result.stopped == 0) continue;
        seen = true;
        EXPECT_EQ(result.stopped, 1);
        EXPECT_LT(result.consumed, row.size());  // the stopped chunk's tiles are left
        // What was published counts, and only that; the tiles from `consumed` on are either
        // resident (published before the stop) or not counted at all.
        EXPECT_EQ(result.filled.size(), result.costs.tilesFilled);
        for (const TileRequest& r : result.filled) EXPECT_TRUE(f.map().resident(r.key));
        size_t resident = 0;
        for (const TileRequest& r : row) resident += f.map().resident(r.key);
        EXPECT_EQ(resident, result.filled.size());
        for (size_t k = 0; k < result.consumed; ++k) EXPECT_TRUE(f.map().resident(row[k].key));
        EXPECT_FALSE(f.map().resident(row.back().key));
    }
    EXPECT_TRUE(seen) << "no deadline landed inside a chunk";
}

TEST(BudgetedFills, CoarserLevelsFirstInTheOrderAskedWithinALevel) {
    std::vector<TileRequest> tiles;
    const uint16_t levels[] = {0, 3, 1, 3, 0, 5, 1};
    for (uint16_t k = 0; k < 7; ++k) tiles.push_back({k, TileKey{0, levels[k], k, 0}});
    orderCoarsestFirst(tiles);
    const uint32_t objects[] = {5, 1, 3, 2, 6, 0, 4};  // asked as 0..6
    for (size_t k = 0; k < 7; ++k) EXPECT_EQ(tiles[k].object, objects[k]) << k;
}

TEST(BudgetedFills, EndAtTheKeptTwentiethOrGiveALateFrameItsShare) {
    const double budget = 0.04, share = 0.1;
    // On time: to 95% of the budget, however little the frame took.
    EXPECT_DOUBLE_EQ(budgetedFillEnd(0.0, budget, share), 0.038);
    EXPECT_DOUBLE_EQ(budgetedFillEnd(0.03, budget, share), 0.038);
    // In the kept twentieth, on time still (the budget itself included): nothing more, a
    // fill would make it late.
    EXPECT_DOUBLE_EQ(budgetedFillEnd(0.038, budget, share), 0.038);
    EXPECT_DOUBLE_EQ(budgetedFillEnd(0.039, budget, share), 0.039);
    EXPECT_DOUBLE_EQ(budgetedFillEnd(budget, budget, share), budget);
    // Past the budget, late anyway: the minimum share on top of what it took.
    EXPECT_DOUBLE_EQ(budgetedFillEnd(0.0401, budget, share), 0.0401 + 0.004);
    EXPECT_DOUBLE_EQ(budgetedFillEnd(0.05, budget, share), 0.05 + 0.004);
    EXPECT_DOUBLE_EQ(budgetedFillEnd(0.05, budget, 0.0), 0.05);
}

}  // namespace
}  // namespace mpshade
