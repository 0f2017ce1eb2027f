// The shader-map store: tiles found only under the digest and key they were written with,
// damaged files never read, clean-up by least recent use, a map that reads a stored tile
// holding exactly what filling it gives, and writers racing on one tile.
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "geometry/error.h"
#include "shadermaps/shader_map.h"
#include "shadermaps/tile_pack_format.h"
#include "shadermaps/tile_store.h"
#include "shading/factoring.h"
#include "shading/program_digest.h"
#include "shading/shader_compiler.h"

namespace mpshade {
namespace {

namespace fs = std::filesystem;

fs::path freshFolder(const std::string& name) {
    const fs::path dir = fs::path(::testing::TempDir()) / ("mpshade_store_" + name);
    fs::remove_all(dir);
    return dir;
}

std::vector<unsigned char> bytes(size_t n, unsigned char seed) {
    std::vector<unsigned char> v(n);
    for (size_t i = 0; i < n; ++i) v[i] = static_cast<unsigned char>(seed + 7 * i);
    return v;
}

// Writes tiles of `map` as one pack.
void writePack(TileStore& store, const Digest128& map, std::vector<uint64_t> keys,
               const std::vector<unsigned char>& tile) {
    std::vector<const unsigned char*> tiles(keys.size(), tile.data());
    store.write(map, keys, tiles, tile.size());
}

// Overwrites the byte of `file` at `offset`.
void putByte(const fs::path& file, size_t offset, char byte) {
    std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(offset));
    f.put(byte);
}

constexpr size_t kHeader = sizeof(pack::TileHeader);

std::vector<fs::path> packs(const fs::path& root) {
    std::vector<fs::path> out;
    for (const auto& e : fs::recursive_directory_iterator(root))
        if (e.path().extension() == ".pack") out.push_back(e.path());
    return out;
}

TEST(TileStore, ReadsWhatWasWrittenUnderItsDigestAndKeyOnly) {
    const fs::path root = freshFolder("roundtrip");
    TileStore store(root);
    const Digest128 map{1, 2}, other{1, 3};
    const std::vector<unsigned char> tile = bytes(1296, 5), second = bytes(1296, 9);
    const std::vector<const unsigned char*> both = {tile.data(), second.data()};
    const std::vector<uint64_t> keys = {42, 44};
    store.write(map, keys, both, tile.size());
    EXPECT_EQ(packs(root).size(), 1u);  // one pack for the fill
    std::vector<unsigned char> out(tile.size());
    ASSERT_TRUE(store.read(map, 42, out));
    EXPECT_EQ(out, tile);
    ASSERT_TRUE(store.read(map, 44, out));
    EXPECT_EQ(out, second);
    EXPECT_FALSE(store.read(other, 42, out));  // another map
    EXPECT_FALSE(store.read(map, 43, out));    // another tile
    std::vector<unsigned char> longer(tile.size() + 4);
    EXPECT_FALSE(store.read(map, 42, longer));  // another tile size: another layout
    EXPECT_EQ(store.counters().loaded.load(), 2u);
    EXPECT_EQ(store.counters().written.load(), 2u);
    // Another process (another store object) finds the pack on disk.
    TileStore later(root);
    ASSERT_TRUE(later.read(map, 44, out));
    EXPECT_EQ(out, second);
}

TEST(TileStore, DamagedTilesAreNeverReadAndRefilledCopiesAre) {
    const fs::path root = freshFolder("damaged");
    const Digest128 map{9, 9};
    const std::vector<unsigned char> tile = bytes(400, 1);
    std::vector<unsigned char> out(tile.size());
    {
        TileStore store(root);
        writePack(store, map, {1, 2}, tile);
    }
    // One byte of tile 1's payload flipped (the first record: after its header).
    putByte(packs(root).at(0), kHeader + 100, static_cast<char>(tile[100] ^ 0x10));
    {
        TileStore store(root);
        EXPECT_FALSE(store.read(map, 1, out));
        EXPECT_EQ(store.counters().damaged.load(), 1u);
        ASSERT_TRUE(store.read(map, 2, out));  // the pack's other tile is whole
        EXPECT_EQ(out, tile);
        writePack(store, map, {1}, tile);  // refilled, as a render would
    }
    {
        // The refilled copy, in the newer pack, is read first: nothing damaged is met.
        TileStore store(root);
        ASSERT_TRUE(store.read(map, 1, out));
        EXPECT_EQ(out, tile);
        EXPECT_EQ(store.counters().damaged.load(), 0u);
    }
    // A pack cut short (a copy interrupted): its index fails, it is removed, its tiles are
    // missing.
    for (const fs::path& p : packs(root)) fs::resize_file(p, fs::file_size(p) - 5);
    TileStore store(root);
    EXPECT_FALSE(store.read(map, 2, out));
    EXPECT_EQ(store.counters().damaged.load(), 2u);
    EXPECT_TRUE(packs(root).empty());
}

// Records (a stored representation's facets): read back as written under their key only; a
// record whose header, size or checksum fails is never read, is counted and removed.
TEST(TileStore, RecordsAreReadAsWrittenAndDamagedOnesNever) {
    const fs::path root = freshFolder("records");
    const Digest128 key{5, 6};
    const std::vector<unsigned char> rep = bytes(3000, 3);
    std::vector<unsigned char> out;
    const fs::path file = root / "reps-v1" / (key.hex() + ".rep");
    // Each case damages the written file one way: a payload byte, the header's tile key
    // (records write 0), its map, the file cut short, a byte added.
    const std::vector<std::pair<const char*, std::function<void()>>> damages = {
        {"payload", [&] { putByte(file, kHeader + 2999, static_cast<char>(rep[2999] ^ 1)); }},
        {"key", [&] { putByte(file, offsetof(pack::TileHeader, key), 1); }},
        {"map", [&] { putByte(file, offsetof(pack::TileHeader, mapHigh), 7); }},
        {"cut", [&] { fs::resize_file(file, fs::file_size(file) - 1); }},
        {"longer", [&] { std::ofstream(file, std::ios::app | std::ios::binary).put(0); }},
    };
    for (const auto& [name, damage] : damages) {
        TileStore store(root);
        store.writeRecord(key, rep);
        ASSERT_TRUE(fs::exists(file));
        ASSERT_TRUE(store.readRecord(key, out)) << name;
        EXPECT_EQ(out, rep);
        EXPECT_FALSE(store.readRecord(Digest128{5, 7}, out));  // another key
        damage();
        EXPECT_FALSE(store.readRecord(key, out)) << name;
        EXPECT_EQ(store.counters().damaged.load(), 1u) << name;
        EXPECT_EQ(store.counters().recordsRead.load(), 1u) << name;
        EXPECT_FALSE(fs::exists(file)) << name;
    }
}

TEST(TileStore, CleanUpRemovesTheMapsUnusedLongestFirst) {
    const fs::path root = freshFolder("gc");
    TileStore store(root);
    const std::vector<unsigned char> tile = bytes(1000, 3);
    const auto now = fs::file_time_type::clock::now();
    for (uint64_t m = 0; m < 3; ++m) {
        const Digest128 map{m, 0};
        StoredMapInfo info;
        info.object = "object" + std::to_string(m);
        info.engine = "engine" + std::to_string(m);
        store.useMap(map, info);
        writePack(store, map, {0, 1, 2, 3}, tile);
        // Map 0 used three hours ago, map 1 two, map 2 one.
        fs::last_write_time(root / TileStore::kTilesFolder / map.hex() / "used",
                            now - std::chrono::hours(3 - m));
    }
    // A temporary file a killed writer left two hours ago, and one being written now.
    const fs::path folder2 = root / TileStore::kTilesFolder / Digest128{2, 0}.hex();
    std::ofstream(folder2 / "x.pack.h.1.2.tmp") << "partial";
    fs::last_write_time(folder2 / "x.pack.h.1.2.tmp", now - std::chrono::hours(2));
    std::ofstream(folder2 / "y.pack.h.1.3.tmp") << "partial";

    // Four tiles with their headers, their index entries and the footer.
    const uint64_t perMap = 4 * (48 + tile.size()) + 4 * 16 + 32;
    EXPECT_EQ(store.bytes(), 3 * perMap);
    // Listed oldest first, with or without their packs counted.
    const std::vector<StoredMapSummary> counted = store.maps(), described = store.maps(false);
    ASSERT_EQ(counted.size(), 3u);
    ASSERT_EQ(described.size(), 3u);
    for (uint64_t m = 0; m < 3; ++m) {
        EXPECT_EQ(counted[m].digest, (Digest128{m, 0}));
        EXPECT_EQ(counted[m].tiles, 4u);
        EXPECT_EQ(counted[m].packs, 1u);
        EXPECT_EQ(counted[m].bytes, perMap);
        EXPECT_EQ(described[m].digest, counted[m].digest);
        EXPECT_EQ(described[m].info.object, "object" + std::to_string(m));
        EXPECT_EQ(described[m].info.engine, "engine" + std::to_string(m));
        EXPECT_EQ(described[m].lastUsed, counted[m].lastUsed);
        EXPECT_EQ(described[m].tiles + described[m].packs + described[m].bytes, 0u);
    }
    // Room for two maps and a half: only the oldest goes.
    EXPECT_EQ(store.gc(2 * perMap + perMap / 2), perMap);
    std::vector<unsigned char> out(tile.size());
    EXPECT_FALSE(store.read({0, 0}, 0, out));
    EXPECT_TRUE(store.read({1, 0}, 0, out));
    EXPECT_TRUE(store.read({2, 0}, 0, out));
    EXPECT_FALSE(fs::exists(folder2 / "x.pack.h.1.2.tmp"));
    EXPECT_TRUE(fs::exists(folder2 / "y.pack.h.1.3.tmp"));
    // Exactly at the budget: nothing more goes.
    EXPECT_EQ(store.gc(2 * perMap), 0u);
    EXPECT_EQ(store.gc(2 * perMap - 1), perMap);
    EXPECT_FALSE(TileStore(root).read({1, 0}, 0, out));
}

// Several stores on one folder, as several processes have: each writes the same tile
// over and over while a reader reads it.
TEST(TileStore, ConcurrentWritersOfOneTileNeverShowAReaderAPartialFile) {
    const fs::path root = freshFolder("race");
    const Digest128 map{5, 5};
    const std::vector<unsigned char> tile = bytes(64 * 1024, 11);
    // Bounded: each write is a pack of its own (3 x 40 x 64 KB).
    std::atomic<int> running{3};
    std::vector<std::thread> writers;
    for (int w = 0; w < 3; ++w)
        writers.emplace_back([&] {
            TileStore other(root);
            for (int k = 0; k < 40; ++k) writePack(other, map, {7}, tile);
            running.fetch_sub(1);
        });
    std::vector<unsigned char> out(tile.size());
    int whole = 0, damaged = 0, wrong = 0;
    while (running.load() > 0) {
        TileStore reader(root);  // a process starting: it scans the packs there now
        if (reader.read(map, 7, out)) {
            ++whole;
            wrong += out != tile;
        }
        damaged += static_cast<int>(reader.counters().damaged.load());
    }
    for (std::thread& t : writers) t.join();
    EXPECT_EQ(damaged, 0);
    EXPECT_EQ(wrong, 0);
    EXPECT_EQ(packs(root).size(), 120u);
    TileStore after(root);
    ASSERT_TRUE(after.read(map, 7, out));
    EXPECT_EQ(out, tile);
    (void)whole;
}

TEST(TileStore, WriteBehindWritesCopiesOfTheTilesByFlushOrDestruction) {
    const fs::path root = freshFolder("behind");
    const Digest128 map{4, 4};
    const std::vector<unsigned char> first = bytes(600, 3), second = bytes(600, 8);
    std::vector<unsigned char> out(first.size());
    {
        TileStore store(root);
        store.setWriteBehind(true);
        std::vector<unsigned char> a = first, b = second;
        const std::vector<const unsigned char*> tiles = {a.data(), b.data()};
        store.write(map, std::vector<uint64_t>{1, 2}, tiles, a.size());
        std::fill(a.begin(), a.end(), 0);  // the caller's slots reused at once
        std::fill(b.begin(), b.end(), 0);
        store.flush();
        EXPECT_EQ(store.counters().written.load(), 2u);
        EXPECT_EQ(packs(root).size(), 1u);
        writePack(store, map, {3}, second);
    }  // the last write still queued: made before the store goes
    TileStore later(root);
    for (uint64_t key : {1, 2, 3}) {
        ASSERT_TRUE(later.read(map, key, out)) << key;
        EXPECT_EQ(out, key == 1 ? first : second) << key;
    }
}

TEST(TileStore, AFolderThatCannotHoldAStoreIsAnInputError) {
    const fs::path file = freshFolder("file");
    std::ofstream(file) << "not a folder";
    EXPECT_THROW(TileStore{file}, InputError);
}

// What a program digest covers.
Digest128 digestOf(const char* source, const ShadingUniforms& uniforms = {}) {
    auto ast = compileShaderText("d.sl", source);
    const FactoredShader f = factorShader(*ast, {}, {});
    ContentHasher h;
    addProgram(h, f.staticPart);
    addUniformsRead(h, f.staticPart, uniforms);
    return h.finish();
}

TEST(ProgramDigest, LayoutIsIgnoredWhatIsComputedIsNot) {
    const char* a = "surface s() { Ci = color(noise(P * 2), 0, 0) * (1 + time); }";
    const char* spaced = "surface s() {\n\n  Ci = color(noise(P*2), 0, 0)\n    * (1 + time);\n}";
    const char* other = "surface s() { Ci = color(noise(P * 3), 0, 0) * (1 + time); }";
    EXPECT_EQ(digestOf(a), digestOf(spaced));
    EXPECT_NE(digestOf(a), digestOf(other));
}

TEST(ProgramDigest, OnlyTheUniformsTheProgramReadsCount) {
    // Static: noise of P; the view and time only in the dynamic part.
    const char* viewFree =
        "surface s() { Ci = color(noise(P * 2), 0, 0) * dot(N, -I) * (1 + time); }";
    ShadingUniforms here, moved;
    moved.eye = {3.0f, 1.0f, 2.0f};
    moved.time = 4.0f;
    EXPECT_EQ(digestOf(viewFree, here), digestOf(viewFree, moved));
    // A bake() of the view stores what the eye sees from here.
    const char* baked = "surface s() { Ci = color(bake(dot(N, -I)), 0, 0) * (1 + time); }";
    EXPECT_NE(digestOf(baked, here), digestOf(baked, moved));
}

// Maps sharing a store: the second finds every tile the first filled, holding its bits.
TEST(TileStore, AMapReadsStoredTilesBitForBitAndFillsTheRest) {
    auto ast = compileShaderText(
        "m.sl",
        "surface n() { Ci = color(noise(P * 1.5), fbm(P * 0.7, 3), noise(P * 6)) * (1 + time); }");
    FactorOptions everything;
    everything.storeAboveCost = 0;
    const FactoredShader f = factorShader(*ast, {}, everything);
    const ShaderKernel kernel(f.staticPart);
    const Surface plane = Plane{4.0f, 4.0f};
    auto store = std::make_shared<TileStore>(freshFolder("maps"));
    ShaderMapOptions options;
    options.resolution = 256;
    options.fillPinnedUpFront = false;
    const StoredTiles stored{store, {77, 1}};
    std::vector<TileKey> keys;
    for (uint16_t t = 0; t < 4; ++t) keys.push_back({0, 2, t, static_cast<uint16_t>(t % 3)});

    ShaderMap first(plane, kernel, {}, options, nullptr, stored);
    const FillStats a = first.fill(keys);
    EXPECT_EQ(a.tiles, 4u);
    EXPECT_EQ(a.tilesLoaded, 0u);

    ShaderMap second(plane, kernel, {}, options, nullptr, stored);
    std::vector<TileKey> more = keys;
    more.push_back({0, 2, 3, 3});  // not stored yet: the corner of the 4 x 4 tiles of level 2
    const FillStats b = second.fill(more);
    EXPECT_EQ(b.tilesLoaded, 4u);
    EXPECT_EQ(b.tiles, 1u);
    // The corner tile with its border but one texel: the one stored tile (2, 2) holds.
    EXPECT_EQ(b.programRuns, 18u * 18u - 1u);
    for (const TileKey& k : keys)
        EXPECT_EQ(std::memcmp(first.tileStorage(first.slotOf(k)),
                              second.tileStorage(second.slotOf(k)), first.tileBytes()),
                  0);
    // The tile filled by the second map next to stored ones: what the first would fill.
    first.fill(more);
    const TileKey last = more.back();
    EXPECT_EQ(std::memcmp(first.tileStorage(first.slotOf(last)),
                          second.tileStorage(second.slotOf(last)), first.tileBytes()),
              0);

    // Another digest finds nothing.
    ShaderMap third(plane, kernel, {}, options, nullptr, {store, {77, 2}});
    EXPECT_EQ(third.fill(keys).tilesLoaded, 0u);
}

}  // namespace
}  // namespace mpshade
