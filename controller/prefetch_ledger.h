// prefetch_ledger.h -- whether prefetched tiles were worth it: a tile prefetched in a
// frame's slack (patent claims 10 and 11) counts as used when a later frame's probes read
// it, and as wasted when it was dropped, its map replaced by a new static run, or no
// frame read it within a patience of frames (it stays resident, an ordinary tile for the
// cache).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "controller/object_slot.h"

namespace mpshade {

class PrefetchLedger {
  public:
    // Tile `key` of object `object`'s map `map` was filled at use stamp `stamp`.
    void record(uint32_t object, const ShaderMap& map, const TileKey& key, uint32_t stamp);
    bool empty() const { return entries_.empty(); }
    // Settles what the frame of use stamp `stamp` shows (its probes have run): counts the
    // tiles it read in `used`, those gone or unread for `patienceFrames` in `wasted`, and
    // forgets both.
    void settle(std::span<const ObjectSlot> slots, uint32_t stamp, int patienceFrames,
                uint64_t& used, uint64_t& wasted);

  private:
    struct Entry {
        uint32_t object;
        const ShaderMap* map;  // compared, never read through once the map may be gone
        TileKey key;
        int slot;
        uint32_t stamp;
    };
    std::vector<Entry> entries_;
};

}  // namespace mpshade
