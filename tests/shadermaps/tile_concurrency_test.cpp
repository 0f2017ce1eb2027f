// Probes running while another thread fills and drops tiles of the same map (a background
// filler evicting under a frame's probes): every probe must read whole tiles of its own
// region -- never a tile half filled, nor a slot reused for another tile while it reads.
// Run under AddressSanitizer and UndefinedBehaviorSanitizer in CI.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <random>
#include <thread>
#include <vector>

#include "shadermaps/probe.h"
#include "shadermaps/tile_pool.h"
#include "shading/factoring.h"
#include "shading/shader_compiler.h"

namespace mpshade {
namespace {

TEST(TileConcurrency, ProbesReadWholeTilesWhileTilesAreFilledAndDropped) {
    // Channels u and v: linear, so a bilinear or trilinear probe of any level returns the
    // query's own (u, v) wherever the level's texel centres surround it -- within [0.15,
    // 0.85] for every level down to the finest always-resident one (4 x 4). A probe that read
    // another tile's storage would be off by a tile's width or more.
    const Surface surface = Plane{4.0f, 4.0f};
    FactorOptions store;
    store.storeAboveCost = 0;
    const FactoredShader factored =
        factorShader(*compileShaderText(
                         "uv.sl", "surface uv() { Ci = color(bake(u), bake(v), 0) * (1 + time); }"),
                     {}, store);
    const ShaderKernel kernel(factored.staticPart);
    ShaderMapOptions options;
    options.resolution = 256;          // level 0: 16 x 16 tiles of 16 x 16 texels
    options.alwaysResidentLevels = 3;  // 4 x 4, 2 x 2, 1 x 1
    ShaderMap map(surface, kernel, ShadingUniforms{}, options);
    const int channels = map.channels();
    ASSERT_GE(channels, 2);

    std::atomic<uint64_t> probes{0}, fallbacks{0}, worst{0};
    uint64_t filled = 0, retired = 0;
    constexpr int kEpochs = 12;
    for (int epoch = 0; epoch < kEpochs; ++epoch) {
        std::atomic<bool> writing{true};
        // A prober takes one level-1 tile of either region at a time and probes 1024 points
        // inside it at level 1's footprint: the probe looks the tile up once and reads it
        // for as long as a fill takes, so a slot reused under it would be read mid-change.
        auto prober = [&](unsigned seed) {
            std::mt19937 rng(seed);
            std::uniform_real_distribution<float> inside(0.1f, 0.9f);
            std::vector<ProbeQuery> q(1024);
            std::vector<float> out(q.size() * static_cast<size_t>(channels));
            std::vector<TileKey> missing(256);
            ProbeOptions probe;
            probe.filter = ProbeFilter::Trilinear;
            const float d = 2.0f / 256.0f;  // two level-0 texels: level 1
            do {
                const int tx = static_cast<int>(rng() % 3) + (rng() % 2 ? 4 : 1);
                const int ty = static_cast<int>(rng() % 3) + (rng() % 2 ? 4 : 1);
                for (ProbeQuery& query : q)
                    query = {0,
                             (static_cast<float>(tx) + inside(rng)) / 8.0f,
                             (static_cast<float>(ty) + inside(rng)) / 8.0f,
                             d,
                             0.0f,
                             0.0f,
                             d};
                ProbeResidency residency{missing.data(), missing.size()};
                probeShaderMap(map, probe, q, out.data(), &residency);
                float err = 0.0f;
                for (size_t i = 0; i < q.size(); ++i) {
                    const float* o = &out[i * static_cast<size_t>(channels)];
                    err = std::max({err, std::abs(o[0] - q[i].u), std::abs(o[1] - q[i].v)});
                }
                uint64_t e = static_cast<uint64_t>(err * 1e6f), seen = worst.load();
                while (e > seen && !worst.compare_exchange_weak(seen, e)) {
                }
                probes += residency.bilinearProbes;
                fallbacks += residency.fallbacks;
            } while (writing.load());
        };
        std::thread a(prober, 11u + static_cast<unsigned>(epoch)),
            b(prober, 97u + static_cast<unsigned>(epoch));
        // The writer: level 1's tiles over two regions, A (tiles 1-3 each way) and B (tiles
        // 4-6), in turns: it drops one region's tiles and fills the other's, so the slots
        // it drops would be the very ones the fill takes if dropping freed them at once --
        // while both probers read both regions.
        uint64_t turnRetired = 0;
        for (int turn = 0; turn < 60; ++turn) {
            const int drop = (turn & 1) ? 4 : 1, add = (turn & 1) ? 1 : 4;
            for (uint16_t ty = 0; ty < 3; ++ty)
                for (uint16_t tx = 0; tx < 3; ++tx) {
                    const TileKey key{0, 1, static_cast<uint16_t>(drop + tx),
                                      static_cast<uint16_t>(drop + ty)};
                    if (map.resident(key)) {
                        map.retire(key.packed());
                        ++turnRetired;
                    }
                }
            std::vector<TileKey> keys;
            for (uint16_t ty = 0; ty < 3; ++ty)
                for (uint16_t tx = 0; tx < 3; ++tx)
                    keys.push_back(
                        {0, 1, static_cast<uint16_t>(add + tx), static_cast<uint16_t>(add + ty)});
            filled += map.fill(keys).tiles;
        }
        retired += turnRetired;
        writing = false;
        a.join();
        b.join();
        // No probe runs now: the dropped tiles' storage may be reused.
        map.pool()->reclaim();
        map.reclaim();
    }
    EXPECT_LT(static_cast<double>(worst.load()) * 1e-6, 1e-4);
    EXPECT_GT(filled, 100u);
    EXPECT_GT(retired, 100u);
    EXPECT_GT(fallbacks.load(), 0u);
    EXPECT_GT(probes.load(), fallbacks.load());
}

TEST(TileConcurrency, AnAbandonedFillPublishesNothingAndKeepsNoStorage) {
    // A background fill is told to stop when a frame starts: the level it was filling must
    // not appear (its tiles may be half evaluated) and its slots must go back to the pool.
    const Surface surface = Plane{4.0f, 4.0f};
    FactorOptions store;
    store.storeAboveCost = 0;
    const FactoredShader factored = factorShader(
        *compileShaderText("uv.sl", "surface uv() { Ci = color(bake(u), bake(v), 0); }"), {},
        store);
    const ShaderKernel kernel(factored.staticPart);
    ShaderMapOptions options;
    options.resolution = 512;  // level 0: 32 x 32 tiles
    options.alwaysResidentLevels = 3;
    ShaderMap map(surface, kernel, ShadingUniforms{}, options);
    const size_t pinnedHeld = map.pool()->tilesHeld(), pinnedResident = map.residentTiles();
    std::vector<TileKey> keys;
    for (uint16_t ty = 0; ty < 32; ++ty)
        for (uint16_t tx = 0; tx < 32; ++tx) keys.push_back({0, 0, tx, ty});
    for (uint16_t ty = 0; ty < 4; ++ty)
        for (uint16_t tx = 0; tx < 4; ++tx) keys.push_back({0, 1, tx, ty});

    // Told before it starts: nothing at all.
    StopSignal stopNow;
    stopNow.request();
    EXPECT_EQ(map.fill(keys, &stopNow).tiles, 0u);
    EXPECT_EQ(map.residentTiles(), pinnedResident);
    EXPECT_EQ(map.pool()->tilesHeld(), pinnedHeld);
    // A deadline already passed: nothing either.
    const StopSignal late(StopSignal::Clock::now() - std::chrono::milliseconds(1));
    EXPECT_EQ(map.fill(keys, &late).tiles, 0u);
    EXPECT_EQ(map.residentTiles(), pinnedResident);
    EXPECT_EQ(map.pool()->tilesHeld(), pinnedHeld);

    // Told while it runs (whenever that lands): the levels published are whole, the one
    // under way is gone, and every slot held is a resident tile's.
    StopSignal stop;
    std::thread stopper([&] {
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
        stop.request();
    });
    uint64_t filled = map.fill(keys, &stop).tiles;
    stopper.join();
    EXPECT_EQ(map.residentTiles(), pinnedResident + filled);
    EXPECT_EQ(map.pool()->tilesHeld(), pinnedHeld + filled);
    EXPECT_TRUE(filled == 0 || filled == 1024 || filled == keys.size()) << filled;
    for (const TileKey& key : keys)
        if (map.resident(key)) {
            float texel[2];
            const int i = key.tx * 16 + 5, j = key.ty * 16 + 9;  // a texel of this tile
            map.texel(key, map.slotOf(key), i, j, texel);
            const float res = static_cast<float>(map.resolution(key.level));
            ASSERT_NEAR(texel[0], (i + 0.5f) / res, 1e-5f);
            ASSERT_NEAR(texel[1], (j + 0.5f) / res, 1e-5f);
        }

    // A deadline 2 ms ahead, with the rest to do: the same, from where the last one stopped.
    const StopSignal soon(StopSignal::Clock::now() + std::chrono::milliseconds(2));
    const uint64_t before = filled;
    filled += map.fill(keys, &soon).tiles;
    EXPECT_EQ(map.residentTiles(), pinnedResident + filled);
    EXPECT_EQ(map.pool()->tilesHeld(), pinnedHeld + filled);
    EXPECT_TRUE(filled == before || filled == 1024 || filled == keys.size()) << filled;

    // Not told: all of it.
    EXPECT_EQ(map.fill(keys).tiles, keys.size() - filled);
}

}  // namespace
}  // namespace mpshade
