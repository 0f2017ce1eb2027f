#include "controller/prefetch_ledger.h"

namespace mpshade {

void PrefetchLedger::record(uint32_t object, const ShaderMap& map, const TileKey& key,
                            uint32_t stamp) {
    const int slot = map.slotOf(key);
    if (slot >= 0) entries_.push_back({object, &map, key, slot, stamp});
}

void PrefetchLedger::settle(std::span<const ObjectSlot> slots, uint32_t stamp, int patienceFrames,
                            uint64_t& used, uint64_t& wasted) {
    size_t kept = 0;
    for (const Entry& e : entries_) {
        const ObjectRepresentation* rep = slots[e.object].representation.get();
        // Dropped, or its map replaced by a new static run, before any probe read it.
        const bool gone = !rep || rep->map.get() != e.map || e.map->slotOf(e.key) != e.slot;
        if (gone) {
            ++wasted;
        } else if (e.map->pool()->lastUse(e.slot) == stamp) {
            // This frame's probes read it (a prediction's probes, run later in a frame,
            // leave an older stamp by the next frame's settling).
            ++used;
        } else if (stamp - e.stamp >= static_cast<uint32_t>(patienceFrames)) {
            ++wasted;
        } else {
            entries_[kept++] = e;
        }
    }
    entries_.resize(kept);
}

}  // namespace mpshade
