// The tile cache: which tiles it drops, how many, and what it never drops.
#include <gtest/gtest.h>

#include <memory>
#include <set>

#include "controller/tile_cache.h"
#include "shadermaps/shader_map.h"
#include "shading/factoring.h"
#include "shading/shader_compiler.h"

namespace mpshade {
namespace {

struct TwoMaps {
    Surface surface = Plane{4.0f, 4.0f};
    FactoredShader factored;
    std::unique_ptr<ShaderKernel> kernel;
    ShadingUniforms uniforms;
    ShaderMapOptions options;
    TilePools pools;
    std::unique_ptr<ShaderMap> a, b;
    TwoMaps() {
        FactorOptions store;
        store.storeAboveCost = 0;
        factored = factorShader(
            *compileShaderText("m.sl", "surface m() { Ci = color(noise(P * 3)) * (1 + time); }"),
            {}, store);
        kernel = std::make_unique<ShaderKernel>(factored.staticPart);
        options.resolution = 256;  // 16 x 16 tiles at level 0
        options.alwaysResidentLevels = 1;
        const size_t bytes = ShaderMap::tileBytesFor(
            options, static_cast<int>(factored.staticPart.channelOutputs.size()));
        a = std::make_unique<ShaderMap>(surface, *kernel, uniforms, options,
                                        pools.forTileBytes(bytes));
        b = std::make_unique<ShaderMap>(surface, *kernel, uniforms, options,
                                        pools.forTileBytes(bytes));
    }
    size_t tileBytes() const { return a->tileBytes(); }
    // Tile t of level 0 (row 0), filled at use stamp `stamp`.
    static TileKey key(uint16_t t) { return {0, 0, t, 0}; }
    void fillAt(ShaderMap& map, uint16_t t, uint32_t stamp) {
        map.setUseStamp(stamp);
        const TileKey k = key(t);
        map.fill({&k, 1});
    }
};

TEST(TileCache, DropsTheLeastRecentlyUsedAcrossMapsDownToItsMargin) {
    TwoMaps m;
    // Stamps 1..12, alternating maps: a holds the odd stamps, b the even ones.
    for (uint16_t t = 0; t < 12; ++t) m.fillAt(t % 2 ? *m.b : *m.a, t, t + 1u);
    const size_t tile = m.tileBytes();
    const size_t held = m.pools.bytesHeld();
    ASSERT_EQ(held, 14 * tile);  // 12 tiles and each map's pinned 1 x 1 level
    // At the budget exactly: it fits, nothing is dropped.
    uint64_t evicted = 0;
    TileCache exact(held);
    EXPECT_TRUE(exact.makeRoom(m.pools, 0, 100, evicted));  // at the budget: fits, no work
    EXPECT_EQ(evicted, 0u);
    // Budget 50 tiles, so the target is 49 (2% under). Held 14 + incoming 37 = 51: the two
    // oldest go (stamps 1 and 2, one in each map), and no more.
    TileCache cache(50 * tile);
    EXPECT_TRUE(cache.makeRoom(m.pools, 37 * tile, 100, evicted));
    EXPECT_EQ(evicted, 2u);
    EXPECT_FALSE(m.a->resident(TwoMaps::key(0)));  // stamp 1
    EXPECT_FALSE(m.b->resident(TwoMaps::key(1)));  // stamp 2
    for (uint16_t t = 2; t < 12; ++t)
        EXPECT_TRUE((t % 2 ? *m.b : *m.a).resident(TwoMaps::key(t))) << t;
    EXPECT_EQ(m.pools.bytesHeld(), 12 * tile);
}

TEST(TileCache, NeverDropsPinnedTilesNorTheFramesOwn) {
    TwoMaps m;
    for (uint16_t t = 0; t < 6; ++t) m.fillAt(*m.a, t, t < 3 ? 1u : 7u);  // 3 old, 3 this frame's
    const size_t tile = m.tileBytes();
    TileCache cache(2 * tile);  // far below what is held: 8 tiles
    uint64_t evicted = 0;
    // Stamp 7 is the current frame: its tiles stay, and so do both pinned tiles.
    EXPECT_FALSE(cache.makeRoom(m.pools, tile, 7, evicted));
    EXPECT_EQ(evicted, 3u);
    for (uint16_t t = 3; t < 6; ++t) EXPECT_TRUE(m.a->resident(TwoMaps::key(t)));
    EXPECT_EQ(m.pools.bytesHeld(), 5 * tile);
    EXPECT_EQ(m.a->residentTiles(), 4u);
    EXPECT_EQ(m.b->residentTiles(), 1u);
}

}  // namespace
}  // namespace mpshade
