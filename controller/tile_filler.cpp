#include "controller/tile_filler.h"

#include <algorithm>

#include "controller/fill_pacer.h"

namespace mpshade {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

void recordResidency(const TilePools& pools, FrameStats& stats) {
    stats.tiles.resident = stats.tiles.residentBytes = stats.tiles.residentPinnedBytes = 0;
    for (const auto& pool : pools.all()) {
        stats.tiles.resident += pool->tilesHeld();
        stats.tiles.residentBytes += pool->bytesHeld();
        stats.tiles.residentPinnedBytes += pool->pinnedBytesHeld();
    }
}

bool TileFiller::makeRoom(size_t incoming, const FillLimits& limits, TileFillResult& result) {
    const TilePools& pools = statics_.tilePools();
    if (limits.room == CacheRoom::RoomLeft)
        return pools.bytesHeld() + incoming <= cache_.budgetBytes();
    const auto start = Clock::now();
    const bool fits = cache_.makeRoom(pools, incoming, limits.useStamp, result.evicted);
    result.roomSeconds += secondsSince(start);
    return fits || limits.room == CacheRoom::EvictAndExceed;
}

void TileFiller::fill(std::span<const TileRequest> tiles,
                      std::span<const ObjectRepresentation* const> representations,
                      const FillLimits& limits, TileFillResult& result) {
    const auto start = Clock::now();
    const bool paced = limits.deadline != Clock::time_point::max();
    result.timing.trace = limits.trace;
    result.timing.frame = limits.frame;
    result.objectTiles.resize(representations.size(), 0);
    FillPacer pacer(tileSeconds_);
    const StopSignal stop(limits.deadline);
    size_t next = 0;
    bool started = false;
    while (next < tiles.size()) {
        const size_t chunk =
            paced
                ? pacer.chunk(std::chrono::duration<double>(limits.deadline - Clock::now()).count())
                : tiles.size();
        if (chunk == 0) break;
        const size_t first = next;
        batch_.clear();
        size_t incoming = 0;
        for (; next < tiles.size() && batch_.size() < chunk; ++next) {
            const TileRequest& r = tiles[next];
            const ObjectRepresentation* rep = representations[r.object];
            if (!rep || !rep->map || rep->map->resident(r.key)) continue;
            batch_.push_back(r);
            incoming += rep->map->tileBytes();
        }
        if (batch_.empty()) continue;
        // Room for the new tiles first, so the maps' storage never outgrows the budget
        // but where a constant-quality frame needs more.
        if (!makeRoom(incoming, limits, result)) {
            next = first;
            break;
        }
        started = true;
        const auto began = Clock::now();
        statics_.fill(batch_, representations, result.costs, &result.timing,
                      paced ? &stop : nullptr);
        const double seconds = secondsSince(began);
        size_t published = 0;
        for (const TileRequest& r : batch_)
            if (representations[r.object]->map->resident(r.key)) {
                ++result.objectTiles[r.object];
                result.filled.push_back(r);
                ++published;
            }
        if (published < batch_.size() && paced && stop.stopped()) {
            // Stopped at the deadline: what was published counts, and this chunk's requests
            // are left (deferred) from its first on; its tiles now resident are skipped by
            // whoever takes them up. Not a measure of a tile's cost.
            ++result.stopped;
            next = first;
            break;
        }
        pacer.filled(seconds, batch_.size());
    }
    if (paced) tileSeconds_ = pacer.remembered();
    result.consumed += next;
    result.seconds += secondsSince(start);
    if (limits.trace && started)
        limits.trace->span("fill", PhaseKind::Static, SpanLevel::Phase, start, Clock::now(), -1,
                           limits.frame);
}

void orderCoarsestFirst(std::vector<TileRequest>& tiles) {
    std::stable_sort(tiles.begin(), tiles.end(), [](const TileRequest& a, const TileRequest& b) {
        return a.key.level > b.key.level;
    });
}

double budgetedFillEnd(double elapsed, double budget, double minimumStaticShare) {
    if (elapsed > budget) return elapsed + minimumStaticShare * budget;
    return std::max(elapsed, 0.95 * budget);
}

}  // namespace mpshade
