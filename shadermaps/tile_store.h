// tile_store.h -- shader-map tiles kept on disk between runs and shared between processes
// and machines (a folder on a shared file system), addressed by content: a tile is found
// by the digest of everything its texels depend on (its map's digest: the static program,
// the uniform values it reads, the geometry, the map's layout; static_phase.cpp) and its
// TileKey. Any change to any of those gives another address, so a stale tile is never
// found; a tile's texels depend on nothing else (shader_map.h: "a tile does not depend on
// what else was resident when it was filled"), so a stored one is what filling it again
// would give, bit for bit.
//
// Layout (docs/store.md): ROOT/tiles-v1/<map digest>/ holds map.json (what the map is, for
// `store info` and `store export`), `used` (its modification time is the map's last use)
// and packs, *.pack: the tiles one fill wrote, each a 48-byte header (magic, map digest,
// tile key, payload size, XXH3-64 of the payload) and the tile's storage as the map holds
// it, then an index of (key, offset) and a footer (magic, count, index offset, index
// checksum). A pack a tile was written to disk separately had cost 60-250 us a tile in file
// creation (the gallery's cold run +85%); a pack costs one file a map and fill, and a run
// merges a map's packs once they are many (compact()). The bytes: tile_pack_format.h.
//
// Concurrency: a pack is written under a name no other writer uses (host, process,
// counter) and renamed into place whole, so readers see whole packs or none. A tile whose checks
// fail (header, size, checksum) is counted as damaged and never read; another copy (a newer
// pack, refilled) is tried, else it is missing and filled again. A pack whose footer is
// damaged is removed. Clean-up (gc()) removes whole maps, least recently used first.
//
// Each tile is filled once across processes: a map's fills hold its fill lock (flock on
// fill.lock in its folder), look again for packs written meanwhile (refresh()), and write
// their pack before letting go (ShaderMap::fill). A reader lists a map's packs when it
// first reads the map and then only when refresh() asks; its own packs it adds as it
// writes them.
//
// Errors: a store that cannot be written (a full disk, no permission) warns once on stderr
// and goes on read-only; rendering never fails because of the store.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <shared_mutex>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "geometry/content_digest.h"

namespace mpshade {

// What a map's tiles are made from, for reports of what a store holds.
struct StoredMapInfo {
    std::string object, shader;
    std::vector<std::string> channelNames;
    int charts = 0, resolution = 0, tileSize = 0, border = 0;
    bool halfPrecision = false;
    // The engine that filled it (engineDigest(), hex): another build of mpshade reads none
    // of its tiles. Empty when unknown (written before it was recorded).
    std::string engine;
};

struct TileStoreCounters {
    std::atomic<uint64_t> loaded{0}, written{0}, damaged{0}, writeFailures{0}, recordsRead{0},
        recordsWritten{0};
};

// One map of a store, as gc() and info() see it.
struct StoredMapSummary {
    Digest128 digest;
    StoredMapInfo info;
    uint64_t tiles = 0, bytes = 0, packs = 0;
    std::filesystem::file_time_type lastUsed;
};

class TileStore {
  public:
    static constexpr const char* kTilesFolder = "tiles-v1";

    // Opens (creating it if needed) the store at `root`. Throws InputError naming the folder
    // when it cannot be made or is not a folder.
    explicit TileStore(std::filesystem::path root);
    ~TileStore();  // writes what write-behind still holds
    TileStore(const TileStore&) = delete;
    TileStore& operator=(const TileStore&) = delete;

    const std::filesystem::path& root() const { return root_; }

    // Reads tile `key` (TileKey::packed()) of map `map` into `out`, whose size must be the
    // tile's storage. True when a whole, checked tile of that size was read. Thread-safe.
    bool read(const Digest128& map, uint64_t key, std::span<unsigned char> out);
    // Writes tiles of map `map` as one pack, before returning: keys[i]'s storage is
    // tiles[i], `tileBytes` long. Failures are counted, never thrown.
    void write(const Digest128& map, std::span<const uint64_t> keys,
               std::span<const unsigned char* const> tiles, size_t tileBytes);
    // With write-behind on, write() copies the tiles and returns; a thread of the store's
    // own writes the pack. For a frame rate: a pack written inside a frame's fill took about
    // 1 ms of it (a file made and renamed). Then a fill no longer writes its pack before
    // letting the map's fill lock go: another process may fill the same tiles meanwhile (the
    // same bits; one copy is read). flush() waits for every write queued so far.
    void setWriteBehind(bool on);
    void flush();

    // While one is held, no other holder -- in this process or another sharing the store, on
    // this machine or another (flock on the map's `fill.lock`) -- fills the map's tiles.
    class FillLock {
      public:
        explicit FillLock(int fd) : fd_(fd) {}
        ~FillLock();
        FillLock(const FillLock&) = delete;
        FillLock& operator=(const FillLock&) = delete;

      private:
        int fd_;
    };
    // Waits for the map's fill lock (null if its file cannot be made: fills go on unlocked).
    std::unique_ptr<FillLock> lockFills(const Digest128& map);
    // Finds the packs other processes added to the map since it was last looked at; whether
    // there were any.
    bool refresh(const Digest128& map);
    // Records the map's description (once per store object and map) and marks it used now.
    void useMap(const Digest128& map, const StoredMapInfo& info);
    // The keys of the tiles stored for `map` (each once), as the packs' indices list them.
    std::vector<uint64_t> storedKeys(const Digest128& map);

    // Records other than tiles (the static phase's built representations), one file each
    // under ROOT/reps-v1/, with the same header and checksum as a tile. readRecord() marks
    // the record used (for clean-up); false if absent or damaged (counted, removed).
    static constexpr const char* kRecordsFolder = "reps-v1";
    bool readRecord(const Digest128& key, std::vector<unsigned char>& out);
    void writeRecord(const Digest128& key, std::span<const unsigned char> bytes);

    const TileStoreCounters& counters() const { return counters_; }

    // Every map in the store, by last use, oldest first. With countPacks false only what
    // each map is and when it was last used are read (map.json), not its packs: tiles,
    // bytes and packs are left 0 (opening every pack of a large store takes a while).
    std::vector<StoredMapSummary> maps(bool countPacks = true) const;
    // Removes maps and records, least recently used first, until the store holds at most
    // `budgetBytes`,
    // and temporary files older than an hour (left by a process that was killed). Returns
    // the bytes removed. Safe while other processes use the store: a tile removed under a
    // reader is missing to it, and filled again.
    uint64_t gc(uint64_t budgetBytes);
    // The bytes the store's packs and records take.
    uint64_t bytes() const;

    // Merges a map's packs into one when it has more than `maxPacks`: every fill writes a
    // pack, so a map played or rendered many times had hundreds, each listed when the map is
    // first read and each opened for every tile read once more than kOpenPacks were open
    // (docs/store.md). The newest whole copy of each tile goes into one new pack, written as
    // any pack is; the others are then removed. Holds the map's fill lock meanwhile, so no
    // process writes to it; a process reading it keeps reading the packs it holds open, and a
    // tile it finds gone is filled again. Returns the packs removed.
    size_t compact(const Digest128& map, size_t maxPacks = kCompactAbovePacks);
    // compact() on every map this object wrote to.
    size_t compactWritten(size_t maxPacks = kCompactAbovePacks);
    static constexpr size_t kCompactAbovePacks = 8;

  private:
    struct Pack;
    struct MapIndex;
    struct WriteBehind;
    void writeNow(const Digest128& map, std::span<const uint64_t> keys,
                  std::span<const unsigned char* const> tiles, size_t tileBytes);
    std::filesystem::path mapFolder(const Digest128& map) const;
    void warnOnce(const std::string& message);
    // The map's index, its packs listed when it is first asked for.
    std::shared_ptr<MapIndex> indexOf(const Digest128& map);
    void scan(const Digest128& map, MapIndex& index);

    std::filesystem::path root_;
    TileStoreCounters counters_;
    std::mutex mutex_;               // guards used_, written_, warned_ and indices_
    std::set<std::string> used_;     // maps marked used by this object
    std::set<std::string> written_;  // maps this object wrote packs of (hex digests)
    std::map<std::string, std::shared_ptr<MapIndex>> indices_;
    bool warned_ = false;
    std::atomic<bool> readOnly_{false};
    // Null: writes are made at once. Shared so the type is complete only where it is made.
    std::shared_ptr<WriteBehind> writeBehind_;
};

// The store's default folder: $MPSHADE_STORE if set, else $XDG_CACHE_HOME/mpshade/store,
// else $HOME/.cache/mpshade/store; empty when none of those is set.
std::filesystem::path defaultStoreFolder();

}  // namespace mpshade
