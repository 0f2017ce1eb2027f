// tile_prefetch.cpp -- MultiphaseRenderer's prefetching mechanisms (the policy that calls
// them is controller/playback.h; the tiles predicted for a frame ahead come from
// controller/tile_predictor.h): tiles next to those recently found missing (patent claim 10:
// adjacency), tiles filled in a frame's slack, and whether what was prefetched was read.
#include <algorithm>
#include <chrono>

#include "controller/multiphase_renderer.h"

namespace mpshade {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

std::vector<TileRequest> MultiphaseRenderer::adjacentTiles() const {
    std::vector<TileRequest> out;
    for (const TileRequest& r : lastMissing_) {
        const ObjectRepresentation* rep = slots_[r.object].representation.get();
        if (!rep || !rep->map) continue;
        const ShaderMap& map = *rep->map;
        const int across = map.tilesU(r.key.chart, r.key.level);
        const int down = map.tilesV(r.key.chart, r.key.level);
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int tx = r.key.tx + dx, ty = r.key.ty + dy;
                if ((dx == 0 && dy == 0) || tx < 0 || ty < 0 || tx >= across || ty >= down)
                    continue;
                const TileKey key{r.key.chart, r.key.level, static_cast<uint16_t>(tx),
                                  static_cast<uint16_t>(ty)};
                if (!map.resident(key)) out.push_back({r.object, key});
            }
    }
    sortUniqueTiles(out);
    return out;
}

double MultiphaseRenderer::prefetch(std::span<const TileRequest> tiles, double seconds,
                                    FrameStats& stats) {
    const auto start = Clock::now();
    const ScopedSpan span(options_.trace, "prefetch", PhaseKind::Static, SpanLevel::Phase, -1,
                          stats.index);
    const BackgroundFiller::Hold paused(filler_.get(),
                                        useStamp_);  // room in the cache is this loop's alone
    const std::vector<const ObjectRepresentation*> maps = representations();
    // A guess never displaces a tile in the cache: only room left is used.
    FillLimits limits = fillLimits(CacheRoom::RoomLeft, stats.index);
    limits.trace = nullptr;
    limits.deadline =
        start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
    TileFillResult fills;
    tiles_.fill(tiles, maps, limits, fills);
    for (const TileRequest& r : fills.filled)
        prefetched_.record(r.object, *maps[r.object]->map, r.key, useStamp_);
    stats.prefetch.filled += fills.costs.tilesFilled;
    return secondsSince(start);
}

void MultiphaseRenderer::settlePrefetched(FrameStats& stats) {
    const auto start = Clock::now();
    prefetched_.settle(slots_, useStamp_, options_.prefetchPatienceFrames, stats.prefetch.used,
                       stats.prefetch.wasted);
    stats.controllerSeconds += secondsSince(start);
}

}  // namespace mpshade
