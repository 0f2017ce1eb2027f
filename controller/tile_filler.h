// tile_filler.h -- the controller's one loop that fills shader-map tiles: for a frame at
// constant quality (every tile its probes found missing, at once), within a frame budget (the
// tiles a frame found missing, coarser first, until its time is spent), and for prefetching (tiles
// guessed for frames ahead, in a frame's slack). Each tile is filled by the static phase
// (StaticPhase::fill: each map's tiles in one batch, maps in parallel); what differs
// between the callers is only their limits (FillLimits): a deadline, and how the tile
// cache's byte budget is kept (patent col. 10: tiles are stored and removed by LRU).
//
// A deadline is kept by pacing (fill_pacer.h): chunks sized to half the time left at the
// most a tile has cost lately, a measure this filler keeps from one call to the next.
#pragma once

#include <chrono>
#include <cstdint>
#include <span>
#include <vector>

#include "controller/tile_cache.h"
#include "phases/frame_stats.h"
#include "phases/phase_trace.h"
#include "phases/static_phase.h"

namespace mpshade {

// How a fill keeps the cache's budget.
enum class CacheRoom {
    // Tiles unused longest are dropped to make room, and the tiles are filled even beyond
    // the budget: a constant-quality frame fills what it needs.
    EvictAndExceed,
    // Tiles unused longest are dropped to make room; a chunk that still does not fit ends
    // the fill (a locked frame rate: the frame reads coarser levels meanwhile).
    EvictWithin,
    // Only the room left is used, never a tile dropped: a guess never displaces a tile.
    RoomLeft,
};

struct FillLimits {
    // Chunks start only while they are expected to end by this moment (paced), and a chunk
    // still running then stops at its next check (ShaderMap::fill's; its tiles under way
    // dropped, left for later as if never started): a tile can cost many times the most
    // one had cost lately (some of a marble column's tiles in the courtyard: 1-2 ms
    // against 0.1-0.3), and such chunks had made locked-rate frames late. The default, no
    // deadline, fills everything asked in one chunk.
    std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();
    CacheRoom room = CacheRoom::EvictAndExceed;
    // The maps' use stamp of the frame being rendered: tiles used at it are never dropped.
    uint32_t useStamp = 0;
    // Where spans go (a "fill" span per call, one per map on the thread that filled it);
    // null: nowhere.
    PhaseTrace* trace = nullptr;
    int64_t frame = -1;
};

// What one fill() did.
struct TileFillResult {
    size_t consumed = 0;  // requests handled, from the front; the rest were left (deferred)
    StaticCosts costs;    // tiles filled, of them built from children, texels, instructions
    FillTiming timing;    // per object: seconds (summed over threads) and instructions
    std::vector<uint32_t> objectTiles;  // per object: tiles filled
    std::vector<TileRequest> filled;    // the requests filled, in order
    uint64_t evicted = 0;               // tiles dropped to make room
    int stopped = 0;  // chunks stopped at the deadline (FillLimits::deadline), their tiles left
    double seconds = 0.0;      // wall time, making room included
    double roomSeconds = 0.0;  // of seconds: making room (the controller's work)
};

class TileFiller {
  public:
    // statics, cache: not owned; must outlive the filler. The cache's budget covers the
    // static phase's tile pools.
    TileFiller(const StaticPhase& statics, TileCache& cache) : statics_(statics), cache_(cache) {}

    // Fills the requests of `tiles`, in order, within `limits`; a request whose object has
    // no map (null in `representations`, indexed by object) or whose tile is resident is
    // skipped. Adds what it did to `result`.
    void fill(std::span<const TileRequest> tiles,
              std::span<const ObjectRepresentation* const> representations,
              const FillLimits& limits, TileFillResult& result);

  private:
    // Makes room for `incoming` bytes as `limits` allow; whether the chunk may be filled.
    bool makeRoom(size_t incoming, const FillLimits& limits, TileFillResult& result);

    const StaticPhase& statics_;
    TileCache& cache_;
    double tileSeconds_ = 0.0;  // the most a tile took lately (0: not measured yet)
    std::vector<TileRequest> batch_;
};

// The tiles every pool holds now, and their bytes (of them the always-resident levels'),
// into stats.tiles.
void recordResidency(const TilePools& pools, FrameStats& stats);

// A budgeted frame's missing tiles in the order its fills take them: coarser levels first
// (a tile there serves four times the surface of one a level finer, and, built from its
// children where they are resident, costs no more), in the order asked within a level.
void orderCoarsestFirst(std::vector<TileRequest>& tiles);

// When a budgeted frame's fills end, seconds from the frame's start, the frame's own work
// having taken `elapsed` of `budget`: a twentieth of the budget is kept for what follows the
// fills, so a frame on time is never made late by them (one already in that twentieth
// fills nothing); a frame already past its budget gets its minimum share of the budget.
double budgetedFillEnd(double elapsed, double budget, double minimumStaticShare);

}  // namespace mpshade
