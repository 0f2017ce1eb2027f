// tile_table.h -- which storage slot holds a tile: an open-addressing hash table (linear
// probing, live keys and tombstones at most 1/2 of it) from packed tile keys to slots. A
// map's finest level is virtual -- up to 2^20 texels per chart side, 2^32 tiles -- so a
// dense table per level is out of the question; only tiles that exist have entries.
//
// Concurrency: find() may run on many threads while one writer (the map's fill, under its
// mutex) inserts and erases. A writer publishes a slot before its key (release; find
// acquires the key), so a key found always comes with its slot. A position goes from empty
// to a key to a tombstone and never back, so a find never reads a slot written for another
// key. Growing (and purging tombstones) builds a new array and publishes it; the old one
// stays readable -- a find may still be walking it -- until reclaim(), which must run when
// no find can be running. A find racing an erase may still return the erased key's slot:
// the slot's storage must outlive it too (TilePool::retire).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace mpshade {

class TileTable {
  public:
    static constexpr uint64_t kEmpty = ~uint64_t{0};
    static constexpr uint64_t kErased = ~uint64_t{0} - 1;

    TileTable() = default;
    TileTable(const TileTable&) = delete;
    TileTable& operator=(const TileTable&) = delete;

    int32_t find(uint64_t key) const {
        const Buckets* b = current_.load(std::memory_order_acquire);
        if (!b) return -1;
        for (size_t i = b->home(key);; i = (i + 1) & b->mask) {
            const uint64_t k = b->keys[i].load(std::memory_order_acquire);
            if (k == key) return b->slots[i].load(std::memory_order_relaxed);
            if (k == kEmpty) return -1;
        }
    }
    // Adds key -> slot (the key must not be present). Writer only.
    void insert(uint64_t key, int32_t slot);
    // Removes a key if present. Writer only.
    void erase(uint64_t key);
    // Frees the arrays replaced by growing. Only when no find() can be running.
    void reclaim() { retired_.clear(); }
    size_t size() const { return size_; }
    template <typename F>
    void forEach(F&& f) const {
        const Buckets* b = current_.load(std::memory_order_acquire);
        for (size_t i = 0; b && i <= b->mask; ++i) {
            const uint64_t k = b->keys[i].load(std::memory_order_relaxed);
            if (k != kEmpty && k != kErased) f(k, b->slots[i].load(std::memory_order_relaxed));
        }
    }
    size_t bytes() const;

  private:
    struct Buckets {
        explicit Buckets(size_t capacity);
        size_t home(uint64_t key) const {
            return static_cast<size_t>((key * 0x9E3779B97F4A7C15ull) >> shift) & mask;
        }
        size_t mask = 0;
        int shift = 64;
        std::unique_ptr<std::atomic<uint64_t>[]> keys;
        std::unique_ptr<std::atomic<int32_t>[]> slots;
    };
    void rebuild(size_t capacity);

    std::atomic<Buckets*> current_{nullptr};
    std::unique_ptr<Buckets> owned_;                 // what current_ points to
    std::vector<std::unique_ptr<Buckets>> retired_;  // replaced, maybe still being read
    size_t size_ = 0, used_ = 0;                     // live keys; live keys and tombstones
};

}  // namespace mpshade
