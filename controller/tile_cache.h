// tile_cache.h -- one LRU cache over every shader map's tiles (patent col. 10: "the tiles
// can be stored in and/or removed from a memory using a least recently used (LRU)
// algorithm"). The tiles live in the renderer's pools (shadermaps/tile_pool.h), one per
// tile size; this keeps all of them under one byte budget by dropping the tiles whose last
// use is oldest, never an always-resident (pinned) tile, nor one the frame being rendered
// has used: a frame that needs more than the budget keeps what it needs.
//
// Threads: makeRoom() runs alone, between a frame's probes (a probe never reads an evicted
// tile: shadermaps/shader_map.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "shadermaps/tile_pool.h"

namespace mpshade {

// Gathers into `out` the tiles of `pools` that may be dropped (not pinned, not retired) last
// used before `before`, and puts in order, oldest first (ties by slot), at least those
// whose storage reaches `bytes`: the front of `out`. Returns how many are in order. Only
// those are sorted: a frame at the budget drops a few hundred of tens of thousands.
size_t oldestTiles(const TilePools& pools, uint32_t before, size_t bytes,
                   std::vector<TilePool::Held>& out);

class TileCache {
  public:
    // budgetBytes: the tiles' storage, pinned levels included, in bytes.
    explicit TileCache(size_t budgetBytes) : budget_(budgetBytes) {}

    size_t budgetBytes() const { return budget_; }
    // Makes room for `incoming` more bytes of tiles: when they would not fit, drops tiles
    // last used before `currentStamp` (the frame's use stamp), oldest first, down to 2%
    // under the budget -- so the next frames do not each evict a few tiles, yet no frame
    // drops a large batch at once (a tenth of a 256 MB cache, 6900 tiles, had cost one frame
    // 16 ms). Counts them in `evicted`; returns whether `incoming` fits the budget now.
    bool makeRoom(const TilePools& pools, size_t incoming, uint32_t currentStamp,
                  uint64_t& evicted);
    // Sizes the candidates' storage for a budget full of the pools' smallest tiles and
    // touches it, so no frame pays for growing it (16 ms of page faults for 69 000
    // candidates on the test machine, the grazing floor's first eviction).
    void reserve(const TilePools& pools);

  private:
    size_t budget_;
    std::vector<TilePool::Held> candidates_;
};

}  // namespace mpshade
