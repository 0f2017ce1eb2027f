#include "controller/tile_cache.h"

#include <algorithm>

#include "shadermaps/shader_map.h"

namespace mpshade {

bool TileCache::makeRoom(const TilePools& pools, size_t incoming, uint32_t currentStamp,
                         uint64_t& evicted) {
    const std::vector<std::shared_ptr<TilePool>> all = pools.all();
    size_t bytes = 0;
    for (const auto& pool : all) bytes += pool->bytesHeld();
    if (bytes + incoming <= budget_) return true;
    const size_t target = budget_ - budget_ / 50;
    const size_t excess = bytes + incoming - std::min(bytes + incoming, target);
    candidates_.clear();
    size_t smallest = 0;
    for (const auto& pool : all) {
        pool->evictable(currentStamp, candidates_);
        smallest = smallest ? std::min(smallest, pool->tileBytes()) : pool->tileBytes();
    }
    // Only the oldest tiles that can cover the excess are put in order (at most this many,
    // each holding at least `smallest` bytes): a frame at the budget evicts a few hundred
    // of tens of thousands. Ties go by slot, so the order does not depend on the sort.
    auto older = [](const TilePool::Held& a, const TilePool::Held& b) {
        return a.lastUse != b.lastUse ? a.lastUse < b.lastUse : a.slot < b.slot;
    };
    const size_t count =
        std::min(candidates_.size(), (excess + smallest - 1) / std::max<size_t>(smallest, 1));
    const auto end = candidates_.begin() + static_cast<std::ptrdiff_t>(count);
    if (count < candidates_.size())
        std::nth_element(candidates_.begin(), end, candidates_.end(), older);
    std::sort(candidates_.begin(), end, older);
    for (size_t i = 0; i < count && bytes + incoming > target; ++i) {
        const TilePool::Held& h = candidates_[i];
        h.owner->evict(h.key);
        bytes -= h.owner->tileBytes();
        ++evicted;
    }
    return bytes + incoming <= budget_;
}

void TileCache::reserve(const TilePools& pools) {
    size_t smallest = 0;
    for (const auto& pool : pools.all())
        smallest = smallest ? std::min(smallest, pool->tileBytes()) : pool->tileBytes();
    if (smallest == 0) return;
    candidates_.resize(std::max(candidates_.size(), budget_ / smallest + 1));
    candidates_.clear();
}

}  // namespace mpshade
