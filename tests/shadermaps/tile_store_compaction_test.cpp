// The store's compaction: a map's packs merged into one only past the limit, each tile's
// newest whole copy kept (an older one where the newest is damaged), other maps untouched,
// and the tiles still read by the process that merged them and by a later one.
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "shadermaps/tile_store.h"

namespace mpshade {
namespace {

namespace fs = std::filesystem;

constexpr size_t kTileBytes = 400;

fs::path freshFolder(const std::string& name) {
    const fs::path dir = fs::path(::testing::TempDir()) / ("mpshade_compact_" + name);
    fs::remove_all(dir);
    return dir;
}

// Pack i's copy of tile `key`: every copy of every tile differs.
std::vector<unsigned char> content(int pack, uint64_t key) {
    std::vector<unsigned char> v(kTileBytes);
    for (size_t i = 0; i < v.size(); ++i)
        v[i] = static_cast<unsigned char>(pack * 31 + static_cast<int>(key) * 7 + 3 * i);
    return v;
}

std::set<fs::path> packsOf(const fs::path& root, const Digest128& map) {
    std::set<fs::path> out;
    const fs::path folder = root / TileStore::kTilesFolder / map.hex();
    if (!fs::is_directory(folder)) return out;
    for (const auto& e : fs::directory_iterator(folder))
        if (e.path().extension() == ".pack") out.insert(e.path());
    return out;
}

// Writes `count` packs of `map`, pack i holding tiles i and i + 1, each pack a minute newer
// than the one before (file times, as another process's would differ). Returns them in order.
std::vector<fs::path> writePacks(TileStore& store, const fs::path& root, const Digest128& map,
                                 int count) {
    std::vector<fs::path> order;
    const auto now = fs::file_time_type::clock::now();
    for (int i = 0; i < count; ++i) {
        const std::set<fs::path> before = packsOf(root, map);
        const std::vector<unsigned char> a = content(i, i), b = content(i, i + 1);
        const std::vector<uint64_t> keys = {static_cast<uint64_t>(i), static_cast<uint64_t>(i + 1)};
        const std::vector<const unsigned char*> tiles = {a.data(), b.data()};
        store.write(map, keys, tiles, kTileBytes);
        std::vector<fs::path> added;
        for (const fs::path& p : packsOf(root, map))
            if (!before.count(p)) added.push_back(p);
        EXPECT_EQ(added.size(), 1u);
        fs::last_write_time(added.at(0), now - std::chrono::minutes(count - i));
        order.push_back(added.at(0));
    }
    return order;
}

TEST(TileStoreCompaction, MergesPastTheLimitKeepingEachTilesNewestCopy) {
    const fs::path root = freshFolder("merge");
    const Digest128 map{5, 6}, other{5, 7};
    TileStore store(root);
    writePacks(store, root, map, 9);
    writePacks(store, root, other, 9);
    std::vector<unsigned char> out(kTileBytes);
    ASSERT_TRUE(store.read(map, 4, out));  // this process's index lists the nine packs

    EXPECT_EQ(store.compact(map, 9), 0u);  // nine packs are not more than nine
    EXPECT_EQ(packsOf(root, map).size(), 9u);
    EXPECT_EQ(store.compact(map, 8), 9u);
    ASSERT_EQ(packsOf(root, map).size(), 1u);
    // Ten tiles once each: headers and storage, the index, the footer.
    EXPECT_EQ(fs::file_size(*packsOf(root, map).begin()), 10 * (48 + kTileBytes) + 10 * 16 + 32);
    EXPECT_EQ(packsOf(root, other).size(), 9u);  // another map is untouched

    // Tile k is in packs k - 1 and k; pack k is the newer. Tile 9 is in pack 8 alone.
    TileStore later(root);
    for (uint64_t k = 0; k <= 9; ++k) {
        const std::vector<unsigned char> newest =
            content(static_cast<int>(std::min<uint64_t>(k, 8)), k);
        ASSERT_TRUE(later.read(map, k, out)) << k;
        EXPECT_EQ(out, newest) << k;
        ASSERT_TRUE(store.read(map, k, out)) << k;  // the process that merged them
        EXPECT_EQ(out, newest) << k;
    }
    EXPECT_FALSE(later.read(map, 10, out));
    EXPECT_EQ(later.counters().damaged.load(), 0u);
    EXPECT_EQ(later.storedKeys(map).size(), 10u);
}

TEST(TileStoreCompaction, ADamagedNewestCopyGivesWayToAnOlderOne) {
    const fs::path root = freshFolder("damaged");
    const Digest128 map{8, 1};
    std::vector<fs::path> order;
    {
        TileStore store(root);
        order = writePacks(store, root, map, 10);
    }
    // Pack 3's first tile (tile 3, the newest copy of it): one payload byte flipped, the
    // pack's time kept.
    const fs::file_time_type written = fs::last_write_time(order.at(3));
    {
        std::fstream f(order.at(3), std::ios::in | std::ios::out | std::ios::binary);
        f.seekg(48 + 17);
        const char c = static_cast<char>(f.get());
        f.seekp(48 + 17);
        f.put(static_cast<char>(c ^ 0x40));
    }
    fs::last_write_time(order.at(3), written);
    TileStore store(root);
    EXPECT_EQ(store.compact(map, 8), 10u);
    EXPECT_EQ(store.counters().damaged.load(), 1u);
    TileStore later(root);
    std::vector<unsigned char> out(kTileBytes);
    ASSERT_TRUE(later.read(map, 3, out));
    EXPECT_EQ(out, content(2, 3));  // pack 2's copy
    ASSERT_TRUE(later.read(map, 4, out));
    EXPECT_EQ(out, content(4, 4));
}

TEST(TileStoreCompaction, ARunCompactsTheMapsItWroteOnly) {
    const fs::path root = freshFolder("written");
    const Digest128 mine{2, 2}, theirs{3, 3};
    {
        TileStore other(root);
        writePacks(other, root, theirs, 12);
    }
    TileStore store(root);
    writePacks(store, root, mine, 12);
    EXPECT_EQ(store.compactWritten(), 12u);
    EXPECT_EQ(packsOf(root, mine).size(), 1u);
    EXPECT_EQ(packsOf(root, theirs).size(), 12u);
}

}  // namespace
}  // namespace mpshade
