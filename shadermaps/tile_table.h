// tile_table.h -- which storage slot holds a tile: an open-addressing hash table (linear
// probing, load at most 1/2) from packed tile keys to slots. A map's finest level is
// virtual -- up to 2^20 texels per chart side, 2^32 tiles -- so a dense table per level is
// out of the question; only tiles that exist have entries.
//
// Concurrency: find() may run on many threads at once; insert() must not run while any
// find() does (the shader map's fills and probes alternate).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace mpshade {

class TileTable {
  public:
    static constexpr uint64_t kEmpty = ~uint64_t{0};

    int32_t find(uint64_t key) const {
        if (keys_.empty()) return -1;
        for (size_t i = hash(key);; i = (i + 1) & mask_) {
            const uint64_t k = keys_[i];
            if (k == key) return slots_[i];
            if (k == kEmpty) return -1;
        }
    }
    // Adds key -> slot (the key must not be present).
    void insert(uint64_t key, int32_t slot);
    // Removes a key if present (for a cache that evicts tiles).
    void erase(uint64_t key);
    size_t size() const { return size_; }
    template <typename F>
    void forEach(F&& f) const {
        for (size_t i = 0; i < keys_.size(); ++i)
            if (keys_[i] != kEmpty) f(keys_[i], slots_[i]);
    }
    size_t bytes() const { return keys_.size() * (sizeof(uint64_t) + sizeof(int32_t)); }

  private:
    size_t hash(uint64_t key) const {
        return static_cast<size_t>((key * 0x9E3779B97F4A7C15ull) >> shift_) & mask_;
    }
    void grow();

    std::vector<uint64_t> keys_;
    std::vector<int32_t> slots_;
    size_t size_ = 0, mask_ = 0;
    int shift_ = 64;
};

}  // namespace mpshade
