// tile_pool.h -- storage for shader-map tiles shared by every map whose tiles have one size:
// slots in blocks of 64, allocated as needed (the storage never moves), reused once freed.
// Per slot it records which map holds it, under which key, whether it is one of that map's
// always-resident levels, and when probes last used it, so a cache can keep all the maps
// under one memory budget by dropping the tiles unused longest (patent col. 10: "the tiles
// can be stored in and/or removed from a memory using a least recently used (LRU)
// algorithm").
//
// Blocks are carved from 8 MiB regions of address space the kernel is asked to back with
// huge pages; pages become resident as tiles are written, at most one 2 MiB page beyond
// what the blocks hold. A warm run's first frame read its tiles from the store 1.6-2.9x
// faster so: with 4 KiB pages it took a page fault a tile.
//
// Each block ends in kSlackBytes of zeros, so probes may load a texel's channels in whole
// vectors (8 floats for 5 channels) even at a block's last texel.
//
// Threads: allocate(), free(), retire() and evictable() may run on several threads at once
// (maps filled in parallel share a pool; a background filler evicts while a frame fills);
// data() and markUsed() of a slot may run alongside all of them (blocks never move, and
// each block keeps its slots' recency). A slot retired while probes may still read it
// (its tile was just evicted) keeps its storage until reclaim(), which runs when no probe
// can be reading: then it is free for reuse.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

namespace mpshade {

class ShaderMap;

class TilePool {
  public:
    static constexpr size_t kSlackBytes = 64;

    explicit TilePool(size_t tileBytes);
    TilePool(const TilePool&) = delete;
    TilePool& operator=(const TilePool&) = delete;

    size_t tileBytes() const { return tileBytes_; }
    // Tiles held, retired ones included (their storage is not free yet).
    size_t tilesHeld() const { return held_.load(std::memory_order_relaxed); }
    size_t bytesHeld() const { return tilesHeld() * tileBytes_; }
    // Of them, the always-resident levels' (never dropped).
    size_t pinnedBytesHeld() const {
        return pinnedHeld_.load(std::memory_order_relaxed) * tileBytes_;
    }
    size_t bytesAllocated() const {
        return blockCount_.load(std::memory_order_relaxed) * kTilesPerBlock * tileBytes_;
    }

    int allocate(ShaderMap* owner, uint64_t key, bool pinned, uint32_t stamp);
    // Frees a slot no probe can be reading.
    void free(int slot);
    // Frees a slot probes may still be reading: its storage is reused only after reclaim().
    void retire(int slot);
    // Frees the retired slots. Only when no probe can be reading them.
    void reclaim();

    unsigned char* data(int slot) {
        return blocks_[static_cast<size_t>(slot) >> kBlockShift]->data +
               static_cast<size_t>(slot & (kTilesPerBlock - 1)) * tileBytes_;
    }
    const unsigned char* data(int slot) const {
        return blocks_[static_cast<size_t>(slot) >> kBlockShift]->data +
               static_cast<size_t>(slot & (kTilesPerBlock - 1)) * tileBytes_;
    }
    static constexpr size_t kMaxTiles = size_t{1} << 22;  // per pool
    void markUsed(int slot, uint32_t stamp) const {
        useOf(slot).store(stamp, std::memory_order_relaxed);
    }
    uint32_t lastUse(int slot) const { return useOf(slot).load(std::memory_order_relaxed); }

    struct Held {
        uint32_t lastUse;
        int slot;
        ShaderMap* owner;
        uint64_t key;
    };
    // Appends the tiles held that may be dropped: not always-resident, not retired, last
    // used before `before`.
    void evictable(uint32_t before, std::vector<Held>& out) const;

  private:
    static constexpr int kBlockShift = 6;
    static constexpr int kTilesPerBlock = 1 << kBlockShift;
    struct Block {
        unsigned char* data = nullptr;  // in one of chunks_
        std::atomic<uint32_t> lastUse[kTilesPerBlock];
    };
    // Storage for blocks, in regions of whole 2 MiB pages the kernel is asked to back with
    // huge pages (madvise): tiles are read all over by probes and first written by fills,
    // and with 4 KiB pages a frame's first fills took a page fault a tile.
    struct Chunk {
        unsigned char* base = nullptr;  // mapped, unless owned
        std::unique_ptr<unsigned char[]> owned;
        size_t bytes = 0, used = 0;
        ~Chunk();
    };
    unsigned char* blockStorage(size_t bytes);
    std::vector<std::unique_ptr<Chunk>> chunks_;
    // Puts an unowned slot back on the free list (under mutex_).
    void release(int slot);
    std::atomic<uint32_t>& useOf(int slot) const {
        return blocks_[static_cast<size_t>(slot) >> kBlockShift]
            ->lastUse[slot & (kTilesPerBlock - 1)];
    }

    size_t tileBytes_;
    std::atomic<size_t> held_{0}, pinnedHeld_{0};
    mutable std::mutex mutex_;
    // Block pointers in an array that never grows: data() reads it while other threads
    // allocate.
    std::unique_ptr<std::unique_ptr<Block>[]> blocks_;
    std::atomic<size_t> blockCount_{0};
    std::vector<int> free_, retired_;
    std::vector<ShaderMap*> owner_;  // per slot; null: free or retired
    std::vector<uint64_t> key_;
    std::vector<uint8_t> pinned_;
};

// The pools of a renderer, one per tile size, created on first use. Thread safe.
class TilePools {
  public:
    std::shared_ptr<TilePool> forTileBytes(size_t tileBytes);
    std::vector<std::shared_ptr<TilePool>> all() const;
    size_t bytesHeld() const;
    size_t smallestTileBytes() const;  // 0: no pool yet

  private:
    mutable std::mutex mutex_;
    std::vector<std::shared_ptr<TilePool>> pools_;
};

}  // namespace mpshade
