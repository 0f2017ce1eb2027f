#include "shadermaps/tile_pool.h"

#include "geometry/error.h"

namespace mpshade {

TilePool::TilePool(size_t tileBytes)
    : tileBytes_(tileBytes),
      blocks_(std::make_unique<std::unique_ptr<unsigned char[]>[]>(kMaxTiles / kTilesPerBlock)) {}

int TilePool::allocate(ShaderMap* owner, uint64_t key, bool pinned, uint32_t stamp) {
    std::lock_guard<std::mutex> lock(mutex_);
    int slot;
    if (!free_.empty()) {
        slot = free_.back();
        free_.pop_back();
    } else {
        slot = static_cast<int>(owner_.size());
        MPSHADE_CHECK(owner_.size() < kMaxTiles);
        if (owner_.size() == blockCount_ * kTilesPerBlock)
            blocks_[blockCount_++] =
                std::make_unique<unsigned char[]>(kTilesPerBlock * tileBytes_ + kSlackBytes);
        owner_.push_back(nullptr);
        key_.push_back(0);
        pinned_.push_back(0);
        lastUse_.push_back(0);
    }
    const size_t s = static_cast<size_t>(slot);
    owner_[s] = owner;
    key_[s] = key;
    pinned_[s] = pinned ? 1 : 0;
    lastUse_[s] = stamp;
    ++held_;
    pinnedHeld_ += pinned ? 1 : 0;
    return slot;
}

void TilePool::free(int slot) {
    std::lock_guard<std::mutex> lock(mutex_);
    const size_t s = static_cast<size_t>(slot);
    MPSHADE_CHECK(s < owner_.size() && owner_[s] != nullptr);
    owner_[s] = nullptr;
    free_.push_back(slot);
    --held_;
    pinnedHeld_ -= pinned_[s];
}

void TilePool::evictable(uint32_t before, std::vector<Held>& out) const {
    for (size_t s = 0; s < owner_.size(); ++s)
        if (owner_[s] && !pinned_[s] && lastUse_[s] < before)
            out.push_back({lastUse_[s], static_cast<int>(s), owner_[s], key_[s]});
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

size_t TilePools::bytesHeld() const {
    std::lock_guard<std::mutex> lock(mutex_);
    size_t bytes = 0;
    for (const auto& pool : pools_) bytes += pool->bytesHeld();
    return bytes;
}

}  // namespace mpshade
