#include "shadermaps/tile_table.h"

#include <utility>

namespace mpshade {

TileTable::Buckets::Buckets(size_t capacity)
    : mask(capacity - 1),
      keys(std::make_unique<std::atomic<uint64_t>[]>(capacity)),
      slots(std::make_unique<std::atomic<int32_t>[]>(capacity)) {
    for (size_t c = capacity; c > 1; c >>= 1) --shift;
    for (size_t i = 0; i < capacity; ++i) {
        keys[i].store(kEmpty, std::memory_order_relaxed);
        slots[i].store(-1, std::memory_order_relaxed);
    }
}

void TileTable::rebuild(size_t capacity) {
    auto next = std::make_unique<Buckets>(capacity);
    forEach([&](uint64_t key, int32_t slot) {
        size_t i = next->home(key);
        while (next->keys[i].load(std::memory_order_relaxed) != kEmpty) i = (i + 1) & next->mask;
        next->slots[i].store(slot, std::memory_order_relaxed);
        next->keys[i].store(key, std::memory_order_relaxed);
    });
    used_ = size_;
    current_.store(next.get(), std::memory_order_release);
    if (owned_) retired_.push_back(std::move(owned_));
    owned_ = std::move(next);
}

void TileTable::insert(uint64_t key, int32_t slot) {
    const size_t capacity = owned_ ? owned_->mask + 1 : 0;
    if (2 * (used_ + 1) > capacity) {
        // Twice the live keys' room; tombstones alone are purged at the same size.
        size_t next = 64;
        while (next < 4 * (size_ + 1)) next *= 2;
        rebuild(std::max(next, capacity));
    }
    Buckets& b = *owned_;
    size_t i = b.home(key);
    while (b.keys[i].load(std::memory_order_relaxed) != kEmpty) i = (i + 1) & b.mask;
    b.slots[i].store(slot, std::memory_order_relaxed);
    b.keys[i].store(key, std::memory_order_release);
    ++size_;
    ++used_;
}

void TileTable::erase(uint64_t key) {
    if (!owned_) return;
    Buckets& b = *owned_;
    for (size_t i = b.home(key);; i = (i + 1) & b.mask) {
        const uint64_t k = b.keys[i].load(std::memory_order_relaxed);
        if (k == kEmpty) return;
        if (k == key) {
            b.keys[i].store(kErased, std::memory_order_release);
            --size_;
            return;
        }
    }
}

size_t TileTable::bytes() const {
    const size_t capacity = owned_ ? owned_->mask + 1 : 0;
    return capacity * (sizeof(uint64_t) + sizeof(int32_t));
}

}  // namespace mpshade
