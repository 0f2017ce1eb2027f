// shader_map.h -- tiled, mip-levelled maps of a shader's static n-tuple over an object's
// charts (patent FIG. 5, claims 5-9): the static part of the factored shader evaluated at
// texel centres, populated on demand, one tile at a time.
//
// Layout. Every chart of the surface is a grid of R x R texels at level 0 (R a power of
// two up to 2^20), with its own pyramid down to 1 x 1, so coarse levels never mix charts.
// Level L is R / 2^L texels wide, cut into square tiles of `tileSize` texels; each tile
// also stores a `border` of texels around it, so a bilinear lookup anywhere in the tile
// reads one tile. Texel (i, j) of level L covers chart coordinates [i, i + 1] / (R / 2^L)
// (likewise j); its value is the static program at the texel centre. A chart whose
// parameterization is stretched has fewer texels along its longer-texelled axis
// (chart_aspect.h, with `chartAspect`): R >> (L + shift) along that axis, at least one,
// so its texels are about square on the surface.
//
// Virtual resolution: R is large enough for the finest footprint any frame asks (by
// default the limit, 2^20, where a float chart coordinate still places a lookup within
// 1/16 texel); tiles exist only once asked for and filled, found through a hash table
// (tile_table.h), so an unused fine level costs nothing.
//
// No seams: border texels beyond a chart's edge are evaluated on the chart across that
// edge (geometry/chart_adjacency.h), the shader being procedural, so a probe straddling a
// chart border interpolates the surface's own values on both sides. Where no chart lies
// across (a plane's rim, a pole, the outer edge of an n-gon's sub-face) the coordinate
// clamps to the edge. Border texels inside the chart are those of the neighbouring tile:
// copied from it when it is resident (a texel's value depends only on its chart point, so
// this is exact), evaluated otherwise; a 16 x 16 tile among resident neighbours runs the
// program 256 times, not 324.
//
// Prefiltering: point-sampled coarse levels alias high-frequency patterns; with
// `Prefilter::Box` a texel of level L > 0 is the mean of the static program over a k x k
// grid inside it (k = min(2^L, supersampleLimit)). Where 2^L <= supersampleLimit those
// samples are the texel centres of the level below, so a tile whose four children are
// resident is built as their mean at a fraction of the cost (only its border evaluated),
// with the same values up to float rounding: a tile does not depend on what else was
// resident when it was filled.
//
// Residency: the coarsest `alwaysResidentLevels` levels of every chart are never evicted,
// and are filled at construction (unless fillPinnedUpFront is off), so a probe always
// finds data: it falls back to the finest resident coarser level (patent col. 10).
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <unordered_map>
#include <vector>

#include "geometry/chart_adjacency.h"
#include "geometry/content_digest.h"
#include "geometry/surface.h"
#include "shadermaps/chart_aspect.h"
#include "shadermaps/tile_pool.h"
#include "shadermaps/tile_table.h"
#include "shading/interpreter.h"
#include "shading/shading_batch.h"
#include "shading/stop_signal.h"

namespace mpshade {

enum class Prefilter { Point, Box };

struct ShaderMapOptions {
    int resolution = 1 << 20;  // level-0 texels per chart side; a power of two, <= 2^20
    int tileSize = 16;  // texels per tile side; a power of two, resolution / tileSize <= 2^16
    int border = 1;     // texels around each tile, >= 1
    bool halfPrecision = false;  // store channels as binary16 (see half_float.h for the error)
    Prefilter prefilter = Prefilter::Box;
    // At most k x k program samples per evaluated texel. 1 (point samples; coarser levels
    // from their children where resident) measured the least error against 64-sample
    // references as well as the least work (docs/shader-maps.md).
    int supersampleLimit = 1;
    int alwaysResidentLevels = 6;  // 1x1 .. 32x32 per chart, never evicted
    // Fill those levels at construction, so a probe always finds data to fall back to (a
    // caller that keeps a frame rate). false: they are filled when first asked for, like
    // any tile, and then never evicted -- for a caller that fills every tile its probes
    // find missing before it shades (constant quality, `render`), which never falls back.
    bool fillPinnedUpFront = true;
    bool seamless = true;  // borders from the neighbouring chart; false: clamp to edge
    // Texels about square on the surface (chart_aspect.h): a stretched chart's longer axis
    // gets fewer. false: every chart R x R at level 0.
    bool chartAspect = true;
};

// A tile: chart, level, and tile column and row within the level.
struct TileKey {
    uint32_t chart = 0;
    uint16_t level = 0;
    uint16_t tx = 0, ty = 0;
    bool operator==(const TileKey&) const = default;
    // 26 bits of chart, 5 of level, 16 each of tx and ty.
    uint64_t packed() const {
        return (uint64_t{chart} << 37) | (uint64_t{level} << 32) | (uint64_t{tx} << 16) | ty;
    }
};

struct FillStats {
    uint64_t tiles = 0;              // evaluated (or built from children)
    uint64_t tilesLoaded = 0;        // read from the store instead (tile_store.h)
    uint64_t tilesFromChildren = 0;  // of tiles: built from the four tiles of the level below
    uint64_t texels = 0;
    uint64_t programRuns = 0;   // static program evaluations (texels x supersamples)
    uint64_t texelsCopied = 0;  // border texels copied from a resident neighbouring tile

    FillStats& operator+=(const FillStats& o) {
        tiles += o.tiles;
        tilesLoaded += o.tilesLoaded;
        tilesFromChildren += o.tilesFromChildren;
        texels += o.texels;
        programRuns += o.programRuns;
        texelsCopied += o.texelsCopied;
        return *this;
    }
};

class TileStore;

// Where a map's tiles are kept between runs (tile_store.h): a tile is looked up there before
// it is filled, and written there once filled.
struct StoredTiles {
    std::shared_ptr<TileStore> store;  // null: nowhere
    Digest128 digest;                  // the map's content digest (see tile_store.h)
};

class ShaderMap {
  public:
    // `staticPart` computes the channels (its channelOutputs); `uniforms` are the static
    // phase's (representative) values, copied. The surface and kernel must outlive the map.
    // `pool` holds the tiles (shared with other maps of the same tile size); null: a pool of
    // its own. Its tileBytes() must be this map's: see tileBytesFor(). `stored`: where tiles
    // are kept between runs, the pinned levels filled at construction included.
    ShaderMap(const Surface& surface, const ShaderKernel& staticPart,
              const ShadingUniforms& uniforms, const ShaderMapOptions& options = {},
              std::shared_ptr<TilePool> pool = nullptr, StoredTiles stored = {});
    ~ShaderMap();
    ShaderMap(const ShaderMap&) = delete;
    ShaderMap& operator=(const ShaderMap&) = delete;

    // The storage of one tile of a map with these options and channels.
    static size_t tileBytesFor(const ShaderMapOptions& options, int channels);

    int channels() const { return channels_; }
    int charts() const { return charts_; }
    int levels() const { return levels_; }
    // The texels a side of `level` of a chart without a shift (chart_aspect.h).
    int resolution(int level) const { return options_.resolution >> level; }
    // Chart `chart`'s texels along u (resolutionU) and v (resolutionV) at `level`, and the
    // tiles they make: at least one each.
    int resolutionU(uint32_t chart, int level) const {
        return std::max(1, options_.resolution >> (level + shiftU(chart)));
    }
    int resolutionV(uint32_t chart, int level) const {
        return std::max(1, options_.resolution >> (level + shiftV(chart)));
    }
    int tilesU(uint32_t chart, int level) const {
        return (resolutionU(chart, level) + options_.tileSize - 1) >> tileShift_;
    }
    int tilesV(uint32_t chart, int level) const {
        return (resolutionV(chart, level) + options_.tileSize - 1) >> tileShift_;
    }
    // Each chart's shifts (chart_aspect.h); 0 for a chart id beyond the surface's.
    int shiftU(uint32_t chart) const { return chart < shiftU_.size() ? shiftU_[chart] : 0; }
    int shiftV(uint32_t chart) const { return chart < shiftV_.size() ? shiftV_[chart] : 0; }
    const ShaderMapOptions& options() const { return options_; }

    bool resident(const TileKey& key) const { return slotOf(key) >= 0; }
    // Fills the tiles that are not resident yet: batched, in parallel, finest level first
    // so coarser tiles can be built from their children. Returns what this call did.
    // Probes may run alongside (on other threads): a tile appears to them once it is whole,
    // with the others of its pass. A pass is every tile asked for, except that a level whose
    // tiles may be built from their children (Prefilter::Box with supersampleLimit >= 2)
    // starts a pass of its own, after the level below is published. One fill (or evict) of
    // a map runs at a time; others wait.
    // `stop` (may be null): checked before each tile begins, after its surface evaluation,
    // between runs of the static shader over ShaderKernel::kLanes (128) points and between
    // streams of occlusion rays; once it says stop (asked to, or its deadline passed), the
    // pass under way is dropped unpublished (its slots freed) and the call returns, so
    // whoever asked waits for a fraction of a tile, and a deadline is overrun by that much.
    FillStats fill(std::span<const TileKey> keys, const StopSignal* stop = nullptr);
    // Fills every tile of the levels in [first, last] (inclusive) of every chart.
    void fillLevels(int first, int last);
    const FillStats& fillStats() const { return fillStats_; }
    size_t residentTiles() const { return residentTiles_.load(std::memory_order_relaxed); }
    size_t bytes() const;      // its tiles' storage and its table
    size_t tileBytes() const;  // storage of one tile
    const std::shared_ptr<TilePool>& pool() const { return pool_; }

    // Recency, for a cache that keeps the maps under a memory budget (tile_pool.h): probes
    // mark the tiles they read with the current use stamp; evict() drops a tile (the pool
    // says which are unused longest), and must not run while probes may read the map;
    // retire() drops it while they may: its storage is reused only after the pool's
    // reclaim(). reclaim() frees the map's own superseded lookup storage; like the pool's,
    // only when no probe of the map can be running.
    void setUseStamp(uint32_t stamp) { useStamp_.store(stamp, std::memory_order_relaxed); }
    uint32_t useStamp() const { return useStamp_.load(std::memory_order_relaxed); }
    void markUsed(int slot) const { pool_->markUsed(slot, useStamp()); }
    void evict(uint64_t key);
    void retire(uint64_t key);
    void reclaim();

    // The tile holding texel (i, j) of a level (clamped to the level).
    TileKey tileOf(uint32_t chart, int level, int i, int j) const {
        return {chart, static_cast<uint16_t>(level),
                static_cast<uint16_t>(std::clamp(i >> tileShift_, 0, tilesU(chart, level) - 1)),
                static_cast<uint16_t>(std::clamp(j >> tileShift_, 0, tilesV(chart, level) - 1))};
    }

    // Reads the channels of texel (i, j), which must lie in the tile `key` or its border:
    // i in [tx * T - border, (tx + 1) * T + border) (likewise j). Writes channels() floats.
    void texel(const TileKey& key, int slot, int i, int j, float* out) const;
    // The storage slot of a resident tile, or -1.
    int slotOf(const TileKey& key) const { return table_.find(key.packed()); }

    // Direct access for probes: a tile's texels, row-major with borders, channels
    // interleaved; stride() texels per row. Exactly one of the two is non-null.
    const float* tileFloats(int slot) const {
        return options_.halfPrecision ? nullptr : reinterpret_cast<const float*>(tileData(slot));
    }
    const uint16_t* tileHalves(int slot) const {
        return options_.halfPrecision ? reinterpret_cast<const uint16_t*>(tileData(slot)) : nullptr;
    }
    // The same storage, untyped: binary16 or float as options().halfPrecision says.
    const unsigned char* tileStorage(int slot) const { return tileData(slot); }
    int stride() const { return stride_; }
    // The slot holding texel (i, j) of a level (clamped to the level), or -1 if that tile is
    // not resident; (li, lj) receive the texel's position in the tile's storage.
    int locate(uint32_t chart, int level, int i, int j, int& li, int& lj) const {
        const TileKey key = tileOf(chart, level, i, j);
        li = i - (key.tx << tileShift_) + options_.border;
        lj = j - (key.ty << tileShift_) + options_.border;
        return table_.find(key.packed());
    }

  private:
    // A fill's tiles not yet published, by packed key.
    using PendingTiles = std::unordered_map<uint64_t, int>;
    const unsigned char* tileData(int slot) const { return pool_->data(slot); }
    unsigned char* tileData(int slot) { return pool_->data(slot); }
    // False if `stop` said stop before the tile was whole.
    bool fillTile(const TileKey& key, int slot, bool fromChildren, const PendingTiles& pending,
                  ShadingBatch& scratch, std::vector<ChartPoint>& points,
                  std::vector<SurfaceSample>& geometry, std::vector<float>& workspace,
                  FillStats& stats, const StopSignal* stop);
    void store(int slot, size_t at, float value);
    void averageChildren(const TileKey& key, int slot, int validW, int validH);
    // The slots of the eight tiles around `key` in its chart and level (-1: not resident,
    // or beyond the level), found once per tile; a border (at most a tile wide) lies in
    // them.
    struct Neighbours {
        int slot[3][3];
    };
    Neighbours neighboursOf(const TileKey& key, const PendingTiles* pending = nullptr) const;
    // The slot of the resident neighbour holding texel (i, j) of key's border, or -1 when
    // it must be evaluated (no such tile resident, or beyond the chart's edge).
    int neighbourSlot(const Neighbours& around, const TileKey& key, int i, int j) const;
    void copyBorders(const TileKey& key, int slot, const PendingTiles& pending, FillStats& stats);
    // Whether tile `key` (level > 0) can be built as the mean of its four children, all of
    // them resident.
    bool childrenResident(const TileKey& key) const;
    // Writes a pass's filled tiles (work[begin, end) with their plan, those not read from
    // the store) to it, as one pack (holding the map's fill lock).
    void storeFilled(std::span<const TileKey> work, size_t begin, size_t end,
                     std::span<const std::pair<int, bool>> plan,
                     std::span<const uint8_t> fromStore);

    const Surface& surface_;
    std::unique_ptr<ChartAdjacency> adjacency_;
    const ShaderKernel& kernel_;
    std::vector<float> params_;
    std::vector<LightSample> lights_;
    ShadingUniforms uniforms_;
    ShaderMapOptions options_;
    int charts_ = 0, channels_ = 0, levels_ = 0;
    int stride_ = 0;                        // texels per tile side with borders
    int tileShift_ = 4;                     // log2(tileSize)
    size_t tileValues_ = 0;                 // floats (or halves) per tile
    std::vector<uint8_t> shiftU_, shiftV_;  // per chart (chart_aspect.h); empty: none
    TileTable table_;
    std::shared_ptr<TilePool> pool_;  // tile storage
    std::atomic<size_t> residentTiles_{0};
    std::atomic<uint32_t> useStamp_{0};
    StoredTiles stored_;
    FillStats fillStats_;
    std::mutex fillMutex_;
};

}  // namespace mpshade
