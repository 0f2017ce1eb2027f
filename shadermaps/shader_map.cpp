#include "shadermaps/shader_map.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <unordered_map>
#include <unordered_set>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "geometry/error.h"
#include "geometry/ray_scene.h"
#include "shadermaps/half_float.h"
#include "shadermaps/tile_store.h"

namespace mpshade {
namespace {

// Per thread: the fill's batches, reused from tile to tile.
struct FillScratch {
    ShadingBatch batch;
    std::vector<ChartPoint> points;
    std::vector<SurfaceSample> geometry;
    std::vector<float> workspace;
    FillStats stats;
};

}  // namespace

size_t ShaderMap::tileBytesFor(const ShaderMapOptions& options, int channels) {
    const size_t stride = static_cast<size_t>(options.tileSize + 2 * options.border);
    return stride * stride * static_cast<size_t>(channels) *
           (options.halfPrecision ? sizeof(uint16_t) : sizeof(float));
}

ShaderMap::ShaderMap(const Surface& surface, const ShaderKernel& staticPart,
                     const ShadingUniforms& uniforms, const ShaderMapOptions& options,
                     std::shared_ptr<TilePool> pool, StoredTiles stored)
    : surface_(surface),
      kernel_(staticPart),
      params_(uniforms.params.begin(), uniforms.params.end()),
      lights_(uniforms.lights.begin(), uniforms.lights.end()),
      uniforms_(uniforms),
      options_(options),
      stored_(std::move(stored)) {
    uniforms_.params = params_;
    uniforms_.lights = lights_;
    MPSHADE_CHECK(options.resolution > 0 && (options.resolution & (options.resolution - 1)) == 0 &&
                  options.resolution <= (1 << 20));
    MPSHADE_CHECK(options.tileSize > 0 && (options.tileSize & (options.tileSize - 1)) == 0);
    MPSHADE_CHECK(options.resolution / options.tileSize <= (1 << 16));
    MPSHADE_CHECK(options.border >= 1 && options.border <= options.tileSize &&
                  options.supersampleLimit >= 1);
    charts_ = chartCount(surface);
    MPSHADE_CHECK(charts_ < (1 << 26));
    if (options.seamless) adjacency_ = std::make_unique<ChartAdjacency>(surface);
    channels_ = static_cast<int>(staticPart.program().channelOutputs.size());
    levels_ = 0;
    for (int r = options.resolution; r >= 1; r >>= 1) ++levels_;
    tileShift_ = 0;
    while ((1 << tileShift_) < options.tileSize) ++tileShift_;
    stride_ = options.tileSize + 2 * options.border;
    tileValues_ = static_cast<size_t>(stride_) * stride_ * static_cast<size_t>(channels_);
    if (options.chartAspect) {
        ChartShifts shifts =
            chartShifts(surface, chartShiftRoom(options.resolution, options.tileSize));
        shiftU_ = std::move(shifts.u);
        shiftV_ = std::move(shifts.v);
    }
    pool_ = pool ? std::move(pool) : std::make_shared<TilePool>(tileBytesFor(options, channels_));
    MPSHADE_CHECK(pool_->tileBytes() == tileBytesFor(options, channels_));
    if (options.alwaysResidentLevels > 0 && options.fillPinnedUpFront)
        fillLevels(std::max(0, levels_ - options.alwaysResidentLevels), levels_ - 1);
}

ShaderMap::~ShaderMap() {
    table_.forEach([&](uint64_t, int32_t slot) { pool_->free(slot); });
}

size_t ShaderMap::tileBytes() const {
    return tileValues_ * (options_.halfPrecision ? sizeof(uint16_t) : sizeof(float));
}

size_t ShaderMap::bytes() const {
    return residentTiles() * tileBytes() + table_.bytes();
}

void ShaderMap::texel(const TileKey& key, int slot, int i, int j, float* out) const {
    const int li = i - (key.tx << tileShift_) + options_.border;
    const int lj = j - (key.ty << tileShift_) + options_.border;
    const size_t at = (static_cast<size_t>(lj) * stride_ + static_cast<size_t>(li)) *
                      static_cast<size_t>(channels_);
    if (const uint16_t* h = tileHalves(slot)) {
        for (int c = 0; c < channels_; ++c) out[c] = halfToFloat(h[at + static_cast<size_t>(c)]);
    } else {
        const float* f = tileFloats(slot);
        for (int c = 0; c < channels_; ++c) out[c] = f[at + static_cast<size_t>(c)];
    }
}

void ShaderMap::store(int slot, size_t at, float value) {
    // A finite value past binary16's range is kept as the largest finite half of its sign,
    // not made infinite: an "auto" map's precision is checked at sampled points only
    // (phases/map_precision.h), and a value between them must not turn into inf * 0 later.
    if (options_.halfPrecision)
        reinterpret_cast<uint16_t*>(tileData(slot))[at] =
            floatToHalf(std::isfinite(value) ? std::clamp(value, -65504.0f, 65504.0f) : value);
    else
        reinterpret_cast<float*>(tileData(slot))[at] = value;
}

// The interior texels of tile `key` as the mean of the 2 x 2 texels of the level below each
// covers (its four children resident: childrenResident()).
void ShaderMap::averageChildren(const TileKey& key, int slot, int validW, int validH) {
    const int resU = resolutionU(key.chart, key.level), resV = resolutionV(key.chart, key.level);
    const int T = options_.tileSize, border = options_.border;
    const size_t channels = static_cast<size_t>(channels_);
    auto interior = [&](int i, int j) {
        return i >= key.tx * T && i < (key.tx + 1) * T && i < resU && j >= key.ty * T &&
               j < (key.ty + 1) * T && j < resV;
    };
    float child[4][64];
    std::vector<float> wide;
    float* c4[4];
    if (channels > 64) {
        wide.resize(4 * channels);
        for (int q = 0; q < 4; ++q) c4[q] = wide.data() + q * channels;
    } else {
        for (int q = 0; q < 4; ++q) c4[q] = child[q];
    }
    for (int lj = 0; lj < validH; ++lj)
        for (int li = 0; li < validW; ++li) {
            const int i = key.tx * T + li - border, j = key.ty * T + lj - border;
            if (!interior(i, j)) continue;
            for (int q = 0; q < 4; ++q) {
                const int ci = 2 * i + (q & 1), cj = 2 * j + (q >> 1);
                const TileKey ck = tileOf(key.chart, key.level - 1, ci, cj);
                texel(ck, slotOf(ck), ci, cj, c4[q]);
            }
            const size_t at =
                (static_cast<size_t>(lj) * stride_ + static_cast<size_t>(li)) * channels;
            for (size_t c = 0; c < channels; ++c)
                store(slot, at + c, 0.25f * ((c4[0][c] + c4[1][c]) + (c4[2][c] + c4[3][c])));
        }
}

bool ShaderMap::fillTile(const TileKey& key, int slot, bool fromChildren,
                         const PendingTiles& pending, ShadingBatch& scratch,
                         std::vector<ChartPoint>& points, std::vector<SurfaceSample>& geometry,
                         std::vector<float>& workspace, FillStats& stats, const StopSignal* stop) {
    // A tile not begun when told to stop is not begun at all: its surface evaluation alone
    // can take a millisecond (a gallery statue's), and every tile of the pass left to start
    // had run it before reaching the kernel's check.
    if (stop && stop->stopped()) return false;
    const int resU = resolutionU(key.chart, key.level), resV = resolutionV(key.chart, key.level);
    const int T = options_.tileSize, border = options_.border;
    // ku x kv samples a texel, at the level-0 texel centres it covers along each axis (fewer
    // along an axis whose level has bottomed out at one texel).
    const bool box = options_.prefilter == Prefilter::Box;
    const int ku = box ? std::min(resolutionU(key.chart, 0) / resU, options_.supersampleLimit) : 1;
    const int kv = box ? std::min(resolutionV(key.chart, 0) / resV, options_.supersampleLimit) : 1;
    // Only the texels this level has, plus the border: a level smaller than a tile leaves
    // the rest of the tile unused (probes clamp to the level).
    const int validW = std::min(stride_, resU - key.tx * T + 2 * border);
    const int validH = std::min(stride_, resV - key.ty * T + 2 * border);
    const size_t channels = static_cast<size_t>(channels_);
    auto texelAt = [&](int li, int lj) {
        return (static_cast<size_t>(lj) * stride_ + static_cast<size_t>(li)) * channels;
    };
    // Interior texels from the four children where they are resident: the mean of the
    // 2 x 2 texels of the level below each covers.
    auto interior = [&](int i, int j) {
        return fromChildren && i >= key.tx * T && i < (key.tx + 1) * T && i < resU &&
               j >= key.ty * T && j < (key.ty + 1) * T && j < resV;
    };
    // Border texels a resident neighbour holds are copied after the batch (copyBorders).
    // Only the border can lie in a neighbour: the tile's own texels are not looked up.
    const Neighbours around = neighboursOf(key, &pending);
    const int ownU0 = key.tx * T, ownV0 = key.ty * T;
    auto skipped = [&](int i, int j) {
        const bool own = i >= ownU0 && i < ownU0 + T && j >= ownV0 && j < ownV0 + T;
        return interior(i, j) || (!own && neighbourSlot(around, key, i, j) >= 0);
    };
    if (fromChildren) {
        averageChildren(key, slot, validW, validH);
        ++stats.tilesFromChildren;
    }
    // The rest evaluated: chart points of every (super)sample of every texel left.
    points.clear();
    for (int lj = 0; lj < validH; ++lj)
        for (int li = 0; li < validW; ++li) {
            const int i = key.tx * T + li - border, j = key.ty * T + lj - border;
            if (skipped(i, j)) continue;
            for (int sj = 0; sj < kv; ++sj)
                for (int si = 0; si < ku; ++si) {
                    const float u =
                        (static_cast<float>(i) + (static_cast<float>(si) + 0.5f) / ku) / resU;
                    const float v =
                        (static_cast<float>(j) + (static_cast<float>(sj) + 0.5f) / kv) / resV;
                    // Inside the chart a point is itself (what resolve() and the clamps
                    // give it); only the border beyond the chart's edge is resolved.
                    const bool inside = u >= 0.0f && u <= 1.0f && v >= 0.0f && v <= 1.0f;
                    points.push_back(inside ? ChartPoint{static_cast<int>(key.chart), u, v}
                                     : adjacency_
                                         ? adjacency_->resolve(static_cast<int>(key.chart), u, v)
                                         : ChartPoint{static_cast<int>(key.chart),
                                                      std::clamp(u, 0.0f, 1.0f),
                                                      std::clamp(v, 0.0f, 1.0f)});
                }
        }
    const size_t n = points.size();
    if (n > 0) {
        geometry.resize(n);
        evaluateBatch(surface_, points, geometry);
        scratch.resize(n, channels);
        for (size_t p = 0; p < n; ++p) {
            const glm::vec3 toP = geometry[p].P - uniforms_.eye;
            const float len = std::sqrt(toP.x * toP.x + toP.y * toP.y + toP.z * toP.z);
            scratch.setPoint(p, geometry[p], points[p],
                             len > 0.0f ? toP / len : glm::vec3(0.0f, 0.0f, -1.0f));
        }
        ShadingCounters counters;
        // A stopped fill ends here, before the kernel's first run (just after the surface
        // evaluation) or within one of its runs.
        if (!kernel_.run(uniforms_, scratch.in, n, scratch.out, workspace, counters, stop))
            return false;
        float* const* channelOut = scratch.out.channels;
        const int k = ku * kv;
        const float inv = 1.0f / static_cast<float>(k);
        float* const floats =
            options_.halfPrecision ? nullptr : reinterpret_cast<float*>(tileData(slot));
        size_t first = 0;
        for (int lj = 0; lj < validH; ++lj)
            for (int li = 0; li < validW; ++li) {
                const int i = key.tx * T + li - border, j = key.ty * T + lj - border;
                if (skipped(i, j)) continue;
                const size_t at = texelAt(li, lj);
                for (size_t c = 0; c < channels; ++c) {
                    float sum = 0.0f;
                    for (int s = 0; s < k; ++s)
                        sum += channelOut[c][first + static_cast<size_t>(s)];
                    if (floats)
                        floats[at + c] = sum * inv;
                    else
                        store(slot, at + c, sum * inv);
                }
                first += static_cast<size_t>(k);
            }
    }
    ++stats.tiles;
    stats.texels += static_cast<uint64_t>(validW) * static_cast<uint64_t>(validH);
    stats.programRuns += n;
    return true;
}

bool ShaderMap::childrenResident(const TileKey& key) const {
    // From the children only where that is exactly what evaluating it would give (their
    // texel centres are its k x k samples), so what a tile holds does not depend on which
    // tiles happened to be resident; not where an axis has bottomed out at one texel (its
    // texel is not the mean of a 2 x 2 block there).
    const int below = key.level - 1;
    if (resolutionU(key.chart, below) != 2 * resolutionU(key.chart, key.level) ||
        resolutionV(key.chart, below) != 2 * resolutionV(key.chart, key.level))
        return false;
    for (int q = 0; q < 4; ++q) {
        const int ctx = std::min(2 * key.tx + (q & 1), tilesU(key.chart, below) - 1);
        const int cty = std::min(2 * key.ty + (q >> 1), tilesV(key.chart, below) - 1);
        if (slotOf({key.chart, static_cast<uint16_t>(below), static_cast<uint16_t>(ctx),
                    static_cast<uint16_t>(cty)}) < 0)
            return false;
    }
    return true;
}

ShaderMap::Neighbours ShaderMap::neighboursOf(const TileKey& key,
                                              const PendingTiles* pending) const {
    Neighbours around;
    const int nu = tilesU(key.chart, key.level), nv = tilesV(key.chart, key.level);
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            const int tx = key.tx + dx, ty = key.ty + dy;
            const bool other = (dx || dy) && tx >= 0 && ty >= 0 && tx < nu && ty < nv;
            const uint64_t packed =
                TileKey{key.chart, key.level, static_cast<uint16_t>(tx), static_cast<uint16_t>(ty)}
                    .packed();
            int slot = other ? table_.find(packed) : -1;
            if (other && slot < 0 && pending) {
                const auto it = pending->find(packed);
                if (it != pending->end()) slot = it->second;
            }
            around.slot[dy + 1][dx + 1] = slot;
        }
    return around;
}

int ShaderMap::neighbourSlot(const Neighbours& around, const TileKey& key, int i, int j) const {
    if (i < 0 || j < 0 || i >= resolutionU(key.chart, key.level) ||
        j >= resolutionV(key.chart, key.level))
        return -1;  // beyond the chart: evaluated
    return around.slot[(j >> tileShift_) - key.ty + 1][(i >> tileShift_) - key.tx + 1];
}

void ShaderMap::copyBorders(const TileKey& key, int slot, const PendingTiles& pending,
                            FillStats& stats) {
    const int T = options_.tileSize, border = options_.border;
    const Neighbours around = neighboursOf(key, &pending);
    // Both tiles store the same type: the texel's channels are copied as they are.
    const size_t texelBytes = tileBytes() / (static_cast<size_t>(stride_) * stride_);
    auto at = [&](int s, int li, int lj) {
        return tileData(s) +
               (static_cast<size_t>(lj) * stride_ + static_cast<size_t>(li)) * texelBytes;
    };
    const int validW =
        std::min(stride_, resolutionU(key.chart, key.level) - key.tx * T + 2 * border);
    const int validH =
        std::min(stride_, resolutionV(key.chart, key.level) - key.ty * T + 2 * border);
    for (int lj = 0; lj < validH; ++lj)
        for (int li = 0; li < validW; ++li) {
            // Only the frame of the tile can lie in a neighbour.
            if (lj >= border && lj < border + T && li == border) li = border + T;
            if (li >= validW) break;
            const int i = key.tx * T + li - border, j = key.ty * T + lj - border;
            const int from = neighbourSlot(around, key, i, j);
            if (from < 0) continue;
            std::memcpy(at(slot, li, lj), at(from, (i & (T - 1)) + border, (j & (T - 1)) + border),
                        texelBytes);
            ++stats.texelsCopied;
        }
}

FillStats ShaderMap::fill(std::span<const TileKey> keys, const StopSignal* stop) {
    std::lock_guard<std::mutex> lock(fillMutex_);
    std::vector<TileKey> work;
    std::unordered_set<uint64_t> seen;
    for (const TileKey& key : keys) {
        MPSHADE_CHECK(key.chart < static_cast<uint32_t>(charts_) && key.level < levels_ &&
                      key.tx < tilesU(key.chart, key.level) &&
                      key.ty < tilesV(key.chart, key.level));
        if (table_.find(key.packed()) >= 0 || !seen.insert(key.packed()).second) continue;
        work.push_back(key);
    }
    if (work.empty()) return {};
    std::stable_sort(work.begin(), work.end(),
                     [](const TileKey& a, const TileKey& b) { return a.level < b.level; });
    // Whether a tile of this level may be built from its children: then its level waits for
    // the one below to be published. Otherwise the levels have nothing to wait for and are
    // filled in one parallel pass: a pass per level had left a core idle at each level's
    // last tiles (the vase's fills, 5-7 levels a frame with a few tiles each, kept 1.6-1.9
    // of 2 cores busy).
    auto buildsFromChildren = [&](int level) {
        return level > 0 && options_.prefilter == Prefilter::Box &&
               (1 << std::min(level, 20)) <= options_.supersampleLimit;
    };
    uint64_t abandonedTiles = 0;  // whole, but in a pass dropped
    uint64_t loadedTiles = 0;     // read from the store, in passes published
    tbb::enumerable_thread_specific<FillScratch> scratch;
    for (size_t begin = 0; begin < work.size();) {
        size_t end = begin;
        while (end < work.size() &&
               (work[end].level == work[begin].level || !buildsFromChildren(work[end].level)))
            ++end;
        // Slots for this pass's tiles, storage grown once; whether each can be built from
        // its children (resident now, this batch's finer levels included).
        std::vector<std::pair<int, bool>> plan(end - begin);
        for (size_t w = begin; w < end; ++w) {
            const TileKey& key = work[w];
            const bool children = buildsFromChildren(key.level) && childrenResident(key);
            const bool pinned = key.level >= levels_ - options_.alwaysResidentLevels;
            const int slot = pool_->allocate(this, key.packed(), pinned, useStamp());
            plan[w - begin] = {slot, children};
        }
        // The pass's tiles are published once whole (probes may be reading the map); till
        // then their borders find one another here.
        PendingTiles pending;
        for (size_t w = begin; w < end; ++w)
            pending.emplace(work[w].packed(), plan[w - begin].first);
        std::atomic<uint64_t> whole{0}, loaded{0};
        std::vector<uint8_t> fromStore(end - begin, 0);
        // Tiles in the store are read; while this process fills the rest, no other sharing
        // the store fills this map (it waits, then reads what this one wrote), so each tile
        // is filled once however many processes ask for it.
        std::unique_ptr<TileStore::FillLock> fillLock;
        if (stored_.store) {
            const auto readStored = [&] {
                tbb::parallel_for(begin, end, [&](size_t w) {
                    if (fromStore[w - begin] ||
                        !stored_.store->read(stored_.digest, work[w].packed(),
                                             {tileData(plan[w - begin].first), tileBytes()}))
                        return;
                    fromStore[w - begin] = 1;
                    loaded.fetch_add(1, std::memory_order_relaxed);
                    whole.fetch_add(1, std::memory_order_relaxed);
                });
            };
            readStored();
            if (loaded.load() < end - begin) {
                fillLock = stored_.store->lockFills(stored_.digest);
                if (stored_.store->refresh(stored_.digest)) readStored();
            }
        }
        tbb::parallel_for(begin, end, [&](size_t w) {
            if (fromStore[w - begin]) return;
            enableFlushToZero();
            FillScratch& s = scratch.local();
            if (fillTile(work[w], plan[w - begin].first, plan[w - begin].second, pending, s.batch,
                         s.points, s.geometry, s.workspace, s.stats, stop))
                whole.fetch_add(1, std::memory_order_relaxed);
        });
        if (whole.load() < end - begin) {
            // Abandoned: none of the pass is published, so no probe can hold its slots.
            for (size_t w = begin; w < end; ++w) pool_->free(plan[w - begin].first);
            abandonedTiles += whole.load() - loaded.load();
            break;
        }
        loadedTiles += loaded.load();
        // A texel is the same wherever it is evaluated (the program sees only its chart
        // point), so borders inside the chart come from the neighbouring tile when that is
        // resident: a 16 x 16 tile with a 1-texel border evaluates 256 texels, not 324. A
        // stored tile came whole. A filled one is stored once whole.
        tbb::parallel_for(begin, end, [&](size_t w) {
            if (fromStore[w - begin]) return;
            copyBorders(work[w], plan[w - begin].first, pending, scratch.local().stats);
        });
        if (stored_.store) storeFilled(work, begin, end, plan, fromStore);
        for (size_t w = begin; w < end; ++w) table_.insert(work[w].packed(), plan[w - begin].first);
        residentTiles_.fetch_add(end - begin, std::memory_order_relaxed);
        begin = end;
    }
    FillStats done;
    for (const FillScratch& s : scratch) done += s.stats;
    done.tiles -= abandonedTiles;
    done.tilesLoaded = loadedTiles;
    fillStats_ += done;
    return done;
}

void ShaderMap::storeFilled(std::span<const TileKey> work, size_t begin, size_t end,
                            std::span<const std::pair<int, bool>> plan,
                            std::span<const uint8_t> fromStore) {
    std::vector<uint64_t> keys;
    std::vector<const unsigned char*> tiles;
    for (size_t w = begin; w < end; ++w)
        if (!fromStore[w - begin]) {
            keys.push_back(work[w].packed());
            tiles.push_back(tileData(plan[w - begin].first));
        }
    stored_.store->write(stored_.digest, keys, tiles, tileBytes());
}

void ShaderMap::evict(uint64_t key) {
    std::lock_guard<std::mutex> lock(fillMutex_);
    const int slot = table_.find(key);
    if (slot < 0) return;  // retired meanwhile by a background filler
    table_.erase(key);
    pool_->free(slot);
    residentTiles_.fetch_sub(1, std::memory_order_relaxed);
}

void ShaderMap::retire(uint64_t key) {
    std::lock_guard<std::mutex> lock(fillMutex_);
    const int slot = table_.find(key);
    if (slot < 0) return;  // dropped already (the owner's view of the pool may be stale)
    table_.erase(key);
    pool_->retire(slot);
    residentTiles_.fetch_sub(1, std::memory_order_relaxed);
}

void ShaderMap::reclaim() {
    std::lock_guard<std::mutex> lock(fillMutex_);
    table_.reclaim();
}

void ShaderMap::fillLevels(int first, int last) {
    std::vector<TileKey> keys;
    for (int chart = 0; chart < charts_; ++chart)
        for (int level = first; level <= last; ++level) {
            const auto c = static_cast<uint32_t>(chart);
            for (int ty = 0; ty < tilesV(c, level); ++ty)
                for (int tx = 0; tx < tilesU(c, level); ++tx)
                    keys.push_back({static_cast<uint32_t>(chart), static_cast<uint16_t>(level),
                                    static_cast<uint16_t>(tx), static_cast<uint16_t>(ty)});
        }
    fill(keys);
}

}  // namespace mpshade
