#include "controller/tile_cache.h"

#include <algorithm>

#include "shadermaps/shader_map.h"

namespace mpshade {

size_t oldestTiles(const TilePools& pools, uint32_t before, size_t bytes,
                   std::vector<TilePool::Held>& out) {
    out.clear();
    for (const auto& pool : pools.all()) pool->evictable(before, out);
    const size_t smallest = pools.smallestTileBytes();
    // At most this many cover `bytes`, each tile holding at least `smallest`.
    const size_t count =
        std::min(out.size(), (bytes + smallest - 1) / std::max<size_t>(smallest, 1));
    auto older = [](const TilePool::Held& a, const TilePool::Held& b) {
        return a.lastUse != b.lastUse ? a.lastUse < b.lastUse : a.slot < b.slot;
    };
    const auto end = out.begin() + static_cast<std::ptrdiff_t>(count);
    if (count < out.size()) std::nth_element(out.begin(), end, out.end(), older);
    std::sort(out.begin(), end, older);
    return count;
}

bool TileCache::makeRoom(const TilePools& pools, size_t incoming, uint32_t currentStamp,
                         uint64_t& evicted) {
    size_t bytes = pools.bytesHeld();
    if (bytes + incoming <= budget_) return true;
    const size_t target = budget_ - budget_ / 50;
    const size_t excess = bytes + incoming - std::min(bytes + incoming, target);
    const size_t count = oldestTiles(pools, currentStamp, excess, candidates_);
    for (size_t i = 0; i < count && bytes + incoming > target; ++i) {
        const TilePool::Held& h = candidates_[i];
        h.owner->evict(h.key);
        bytes -= h.owner->tileBytes();
        ++evicted;
    }
    return bytes + incoming <= budget_;
}

void TileCache::reserve(const TilePools& pools) {
    const size_t smallest = pools.smallestTileBytes();
    if (smallest == 0) return;
    candidates_.resize(std::max(candidates_.size(), budget_ / smallest + 1));
    candidates_.clear();
}

}  // namespace mpshade
