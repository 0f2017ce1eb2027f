#include "shadermaps/shader_map.h"

#include <algorithm>
#include <cmath>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "geometry/error.h"
#include "geometry/ray_scene.h"
#include "shadermaps/half_float.h"

namespace mpshade {

ShaderMap::ShaderMap(const Surface& surface, const ShaderKernel& staticPart,
                     const ShadingUniforms& uniforms, const ShaderMapOptions& options)
    : surface_(surface), kernel_(staticPart), uniforms_(uniforms), options_(options) {
    MPSHADE_CHECK(options.resolution > 0 && (options.resolution & (options.resolution - 1)) == 0);
    MPSHADE_CHECK(options.tileSize > 0 && options.border >= 1);
    charts_ = chartCount(surface);
    if (options.seamless) adjacency_ = std::make_unique<ChartAdjacency>(surface);
    channels_ = static_cast<int>(staticPart.program().channelOutputs.size());
    levels_ = 0;
    for (int r = options.resolution; r >= 1; r >>= 1) ++levels_;
    MPSHADE_CHECK((options.tileSize & (options.tileSize - 1)) == 0);
    while ((1 << tileShift_) > options.tileSize) --tileShift_;
    while ((1 << tileShift_) < options.tileSize) ++tileShift_;
    stride_ = options.tileSize + 2 * options.border;
    tileValues_ = static_cast<size_t>(stride_) * stride_ * static_cast<size_t>(channels_);
    for (int level = 0; level < levels_; ++level) tilesPerSide_.push_back(tilesPerSide(level));
    levelOffset_.resize(static_cast<size_t>(levels_) + 1, 0);
    for (int level = 0; level < levels_; ++level) {
        const size_t side = static_cast<size_t>(tilesPerSide(level));
        levelOffset_[static_cast<size_t>(level) + 1] =
            levelOffset_[static_cast<size_t>(level)] + side * side;
    }
    tilesPerChart_ = levelOffset_.back();
    slot_.assign(tilesPerChart_ * static_cast<size_t>(charts_), -1);
    const int coarsest = std::max(0, levels_ - options.alwaysResidentLevels);
    fillLevels(coarsest, levels_ - 1);
}

int ShaderMap::tilesPerSide(int level) const {
    return (resolution(level) + options_.tileSize - 1) / options_.tileSize;
}

size_t ShaderMap::tileIndex(const TileKey& key) const {
    return static_cast<size_t>(key.chart) * tilesPerChart_ + levelOffset_[key.level] +
           static_cast<size_t>(key.ty) * static_cast<size_t>(tilesPerSide(key.level)) + key.tx;
}

int ShaderMap::slotOf(const TileKey& key) const {
    return slot_[tileIndex(key)];
}

TileKey ShaderMap::tileOf(uint32_t chart, int level, int i, int j) const {
    const int n = tilesPerSide(level);
    const int tx = std::clamp(i / options_.tileSize, 0, n - 1),
              ty = std::clamp(j / options_.tileSize, 0, n - 1);
    return {chart, static_cast<uint16_t>(level), static_cast<uint16_t>(tx),
            static_cast<uint16_t>(ty)};
}

size_t ShaderMap::bytes() const {
    return data_.size() * sizeof(float) + halfData_.size() * sizeof(uint16_t) +
           slot_.size() * sizeof(int32_t);
}

void ShaderMap::texel(const TileKey& key, int slot, int i, int j, float* out) const {
    const int li = i - key.tx * options_.tileSize + options_.border;
    const int lj = j - key.ty * options_.tileSize + options_.border;
    const size_t at = ((static_cast<size_t>(slot) * stride_ + static_cast<size_t>(lj)) * stride_ +
                       static_cast<size_t>(li)) *
                      static_cast<size_t>(channels_);
    if (options_.halfPrecision) {
        for (int c = 0; c < channels_; ++c)
            out[c] = halfToFloat(halfData_[at + static_cast<size_t>(c)]);
    } else {
        for (int c = 0; c < channels_; ++c) out[c] = data_[at + static_cast<size_t>(c)];
    }
}

void ShaderMap::fillTile(const TileKey& key, int slot, ShadingBatch& scratch, FillStats& stats) {
    const int res = resolution(key.level);
    const int k = options_.prefilter == Prefilter::Box
                      ? std::min(1 << key.level, options_.supersampleLimit)
                      : 1;
    const int texels = stride_ * stride_;
    // Only the texels this level has, plus the border: a level smaller than a tile leaves
    // the rest of the tile unused (probes clamp to the level).
    const int validW = std::min(stride_, res - key.tx * options_.tileSize + 2 * options_.border);
    const int validH = std::min(stride_, res - key.ty * options_.tileSize + 2 * options_.border);
    const size_t n =
        static_cast<size_t>(validW) * static_cast<size_t>(validH) * static_cast<size_t>(k * k);
    // Chart points of every (super)sample of every valid texel, borders included.
    std::vector<ChartPoint> points(n);
    size_t p = 0;
    for (int lj = 0; lj < validH; ++lj)
        for (int li = 0; li < validW; ++li) {
            const int i = key.tx * options_.tileSize + li - options_.border;
            const int j = key.ty * options_.tileSize + lj - options_.border;
            for (int sj = 0; sj < k; ++sj)
                for (int si = 0; si < k; ++si) {
                    const float u = (static_cast<float>(i) +
                                     (static_cast<float>(si) + 0.5f) / static_cast<float>(k)) /
                                    res;
                    const float v = (static_cast<float>(j) +
                                     (static_cast<float>(sj) + 0.5f) / static_cast<float>(k)) /
                                    res;
                    points[p++] =
                        adjacency_
                            ? adjacency_->resolve(static_cast<int>(key.chart), u, v)
                            : ChartPoint{static_cast<int>(key.chart), std::clamp(u, 0.0f, 1.0f),
                                         std::clamp(v, 0.0f, 1.0f)};
                }
        }
    std::vector<SurfaceSample> geometry(n);
    evaluateBatch(surface_, points, geometry);
    scratch.resize(n, static_cast<size_t>(channels_));
    for (size_t i = 0; i < n; ++i) {
        const glm::vec3 toP = geometry[i].P - uniforms_.eye;
        const float len = std::sqrt(toP.x * toP.x + toP.y * toP.y + toP.z * toP.z);
        scratch.setPoint(i, geometry[i], points[i],
                         len > 0.0f ? toP / len : glm::vec3(0.0f, 0.0f, -1.0f));
    }
    std::vector<float> workspace;
    ShadingCounters counters;
    kernel_.run(uniforms_, scratch.in, n, scratch.out, workspace, counters);
    float* const* channelOut = scratch.out.channels;
    // Box-average the supersamples of each texel into the tile, channel-interleaved.
    const size_t base =
        static_cast<size_t>(slot) * static_cast<size_t>(texels) * static_cast<size_t>(channels_);
    const float inv = 1.0f / static_cast<float>(k * k);
    for (int lj = 0; lj < validH; ++lj)
        for (int li = 0; li < validW; ++li) {
            const size_t first =
                (static_cast<size_t>(lj) * static_cast<size_t>(validW) + static_cast<size_t>(li)) *
                static_cast<size_t>(k * k);
            const size_t texel =
                static_cast<size_t>(lj) * static_cast<size_t>(stride_) + static_cast<size_t>(li);
            for (int c = 0; c < channels_; ++c) {
                float sum = 0.0f;
                for (int s = 0; s < k * k; ++s)
                    sum += channelOut[static_cast<size_t>(c)][first + static_cast<size_t>(s)];
                const size_t at =
                    base + texel * static_cast<size_t>(channels_) + static_cast<size_t>(c);
                if (options_.halfPrecision)
                    halfData_[at] = floatToHalf(sum * inv);
                else
                    data_[at] = sum * inv;
            }
        }
    ++stats.tiles;
    stats.texels += static_cast<uint64_t>(validW) * static_cast<uint64_t>(validH);
    stats.programRuns += n;
}

void ShaderMap::fill(std::span<const TileKey> keys) {
    std::lock_guard<std::mutex> lock(fillMutex_);
    // Assign slots to the new tiles first, growing the storage once.
    std::vector<std::pair<TileKey, int>> work;
    for (const TileKey& key : keys) {
        int32_t& slot = slot_[tileIndex(key)];
        if (slot >= 0) continue;
        slot = static_cast<int32_t>(residentTiles_++);
        work.emplace_back(key, slot);
    }
    if (work.empty()) return;
    const size_t perTile = static_cast<size_t>(stride_) * stride_ * static_cast<size_t>(channels_);
    if (options_.halfPrecision)
        halfData_.resize(residentTiles_ * perTile);
    else
        data_.resize(residentTiles_ * perTile);
    tbb::enumerable_thread_specific<ShadingBatch> scratch;
    tbb::enumerable_thread_specific<FillStats> stats;
    tbb::parallel_for(size_t{0}, work.size(), [&](size_t w) {
        enableFlushToZero();
        fillTile(work[w].first, work[w].second, scratch.local(), stats.local());
    });
    for (const FillStats& s : stats) {
        fillStats_.tiles += s.tiles;
        fillStats_.texels += s.texels;
        fillStats_.programRuns += s.programRuns;
    }
}

void ShaderMap::fillLevels(int first, int last) {
    std::vector<TileKey> keys;
    for (int chart = 0; chart < charts_; ++chart)
        for (int level = first; level <= last; ++level) {
            const int n = tilesPerSide(level);
            for (int ty = 0; ty < n; ++ty)
                for (int tx = 0; tx < n; ++tx)
                    keys.push_back({static_cast<uint32_t>(chart), static_cast<uint16_t>(level),
                                    static_cast<uint16_t>(tx), static_cast<uint16_t>(ty)});
        }
    fill(keys);
}

}  // namespace mpshade
