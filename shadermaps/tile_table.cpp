#include "shadermaps/tile_table.h"

#include <utility>

namespace mpshade {

void TileTable::grow() {
    std::vector<uint64_t> keys = std::move(keys_);
    std::vector<int32_t> slots = std::move(slots_);
    const size_t capacity = keys.empty() ? 64 : keys.size() * 2;
    keys_.assign(capacity, kEmpty);
    slots_.assign(capacity, -1);
    mask_ = capacity - 1;
    shift_ = 64;
    for (size_t c = capacity; c > 1; c >>= 1) --shift_;
    size_ = 0;
    for (size_t i = 0; i < keys.size(); ++i)
        if (keys[i] != kEmpty) insert(keys[i], slots[i]);
}

void TileTable::insert(uint64_t key, int32_t slot) {
    if (2 * (size_ + 1) > keys_.size()) grow();
    size_t i = hash(key);
    while (keys_[i] != kEmpty) i = (i + 1) & mask_;
    keys_[i] = key;
    slots_[i] = slot;
    ++size_;
}

void TileTable::erase(uint64_t key) {
    if (keys_.empty()) return;
    size_t i = hash(key);
    while (keys_[i] != key) {
        if (keys_[i] == kEmpty) return;
        i = (i + 1) & mask_;
    }
    // Backward-shift deletion keeps every probe sequence unbroken without tombstones.
    for (size_t j = (i + 1) & mask_; keys_[j] != kEmpty; j = (j + 1) & mask_) {
        const size_t home = hash(keys_[j]);
        // Move j into the hole at i if its home is not cyclically in (i, j].
        const bool between = i <= j ? (i < home && home <= j) : (i < home || home <= j);
        if (!between) {
            keys_[i] = keys_[j];
            slots_[i] = slots_[j];
            i = j;
        }
    }
    keys_[i] = kEmpty;
    slots_[i] = -1;
    --size_;
}

}  // namespace mpshade
