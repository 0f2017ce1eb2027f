#include "shadermaps/tile_pool.h"

#include <algorithm>
#include <cstring>

#include "geometry/error.h"

namespace mpshade {

TilePool::TilePool(size_t tileBytes)
    : tileBytes_(tileBytes),
      blocks_(std::make_unique<std::unique_ptr<Block>[]>(kMaxTiles / kTilesPerBlock)) {}

int TilePool::allocate(ShaderMap* owner, uint64_t key, bool pinned, uint32_t stamp) {
    std::lock_guard<std::mutex> lock(mutex_);
    int slot;
    if (!free_.empty()) {
        slot = free_.back();
        free_.pop_back();
    } else {
        slot = static_cast<int>(owner_.size());
        MPSHADE_CHECK(owner_.size() < kMaxTiles);
        const size_t blocks = blockCount_.load(std::memory_order_relaxed);
        if (owner_.size() == blocks * kTilesPerBlock) {
            auto block = std::make_unique<Block>();
            // Not zeroed: a fill writes every texel a probe can read (a reused slot holds an
            // old tile's texels anyway), and zeroing took 6.7% of the grazing floor's frames
            // under perf (a pass over memory the fill then writes). The slack, read only by
            // whole-vector loads whose extra lanes are dropped, is zeroed.
            const size_t bytes = kTilesPerBlock * tileBytes_;
            block->data = std::make_unique_for_overwrite<unsigned char[]>(bytes + kSlackBytes);
            std::memset(block->data.get() + bytes, 0, kSlackBytes);
            for (std::atomic<uint32_t>& use : block->lastUse)
                use.store(0, std::memory_order_relaxed);
            blocks_[blocks] = std::move(block);
            blockCount_.store(blocks + 1, std::memory_order_relaxed);
        }
        owner_.push_back(nullptr);
        key_.push_back(0);
        pinned_.push_back(0);
    }
    const size_t s = static_cast<size_t>(slot);
    owner_[s] = owner;
    key_[s] = key;
    pinned_[s] = pinned ? 1 : 0;
    useOf(slot).store(stamp, std::memory_order_relaxed);
    held_.fetch_add(1, std::memory_order_relaxed);
    if (pinned) pinnedHeld_.fetch_add(1, std::memory_order_relaxed);
    return slot;
}

void TilePool::release(int slot) {
    free_.push_back(slot);
    held_.fetch_sub(1, std::memory_order_relaxed);
    if (pinned_[static_cast<size_t>(slot)]) pinnedHeld_.fetch_sub(1, std::memory_order_relaxed);
}

void TilePool::free(int slot) {
    std::lock_guard<std::mutex> lock(mutex_);
    const size_t s = static_cast<size_t>(slot);
    MPSHADE_CHECK(s < owner_.size() && owner_[s] != nullptr);
    owner_[s] = nullptr;
    release(slot);
}

void TilePool::retire(int slot) {
    std::lock_guard<std::mutex> lock(mutex_);
    const size_t s = static_cast<size_t>(slot);
    MPSHADE_CHECK(s < owner_.size() && owner_[s] != nullptr);
    owner_[s] = nullptr;
    retired_.push_back(slot);
}

void TilePool::reclaim() {
    std::lock_guard<std::mutex> lock(mutex_);
    for (int slot : retired_) release(slot);
    retired_.clear();
}

void TilePool::evictable(uint32_t before, std::vector<Held>& out) const {
    std::lock_guard<std::mutex> lock(mutex_);
    for (size_t s = 0; s < owner_.size(); ++s) {
        if (!owner_[s] || pinned_[s]) continue;
        const uint32_t use = lastUse(static_cast<int>(s));
        if (use < before) out.push_back({use, static_cast<int>(s), owner_[s], key_[s]});
    }
}

std::shared_ptr<TilePool> TilePools::forTileBytes(size_t tileBytes) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& pool : pools_)
        if (pool->tileBytes() == tileBytes) return pool;
    pools_.push_back(std::make_shared<TilePool>(tileBytes));
    return pools_.back();
}

std::vector<std::shared_ptr<TilePool>> TilePools::all() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return pools_;
}

size_t TilePools::smallestTileBytes() const {
    std::lock_guard<std::mutex> lock(mutex_);
    size_t smallest = 0;
    for (const auto& pool : pools_)
        smallest = smallest ? std::min(smallest, pool->tileBytes()) : pool->tileBytes();
    return smallest;
}

size_t TilePools::bytesHeld() const {
    std::lock_guard<std::mutex> lock(mutex_);
    size_t bytes = 0;
    for (const auto& pool : pools_) bytes += pool->bytesHeld();
    return bytes;
}

}  // namespace mpshade
