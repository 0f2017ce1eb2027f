// tile_prefetch.cpp -- MultiphaseRenderer's prefetching mechanisms (the policy that calls
// them is controller/playback.h): tiles predicted for a frame ahead by a low-resolution
// dynamic phase (patent claim 11: "a low resolution version of the ... frames" tells which
// tiles will be needed), tiles next to those recently lacked (claim 10: adjacency), filled
// in a frame's slack; and whether what was prefetched was read.
#include <algorithm>
#include <chrono>

#include <cmath>

#include "controller/multiphase_renderer.h"

namespace mpshade {
namespace {

using Clock = std::chrono::steady_clock;

// A shading point's probe footprint in pixels at `rate` (dynamic_phase.h), before
// DynamicOptions::footprintScale.
float footprintPixels(ShadingRate rate, int spp) {
    switch (rate) {
        case ShadingRate::Sample:
            return 1.0f / std::sqrt(static_cast<float>(spp));
        case ShadingRate::Pixel:
            return 0.5f;
        case ShadingRate::Quad:
            return 1.0f;
    }
    return 0.5f;
}

}  // namespace

std::vector<TileRequest> MultiphaseRenderer::predictTiles(int frame, const RenderOptions& options,
                                                          int divisor, double& seconds,
                                                          Clock::time_point deadline) {
    const auto start = Clock::now();
    const ScopedSpan span(options_.trace, "predict tiles", PhaseKind::Static, SpanLevel::Phase, -1,
                          frame);
    divisor = std::max(1, divisor);
    const int width =
        std::max(1, (options.width > 0 ? options.width : scene_.settings.width) / divisor);
    const int height =
        std::max(1, (options.height > 0 ? options.height : scene_.settings.height) / divisor);
    const int spp =
        options.samplesPerPixel > 0 ? options.samplesPerPixel : scene_.settings.samplesPerPixel;
    predictState_ = frameStateAt(resources_, frame, width, height, 1);
    if (!predictLayout_ || !predictLayout_->matches(width, height, 1, options.seed, options.filter))
        predictLayout_ =
            std::make_shared<const SampleLayout>(width, height, 1, options.seed, options.filter);
    if (!predictor_) predictor_ = std::make_unique<DynamicPhase>(scene_);
    const size_t n = scene_.objects.size();
    std::vector<const ObjectRepresentation*> drawn(n, nullptr);
    for (size_t i = 0; i < n; ++i)
        if (slots_[i].representation &&
            objectInView(*scene_.objects[i].surface, predictState_.objects[i],
                         predictState_.camera))
            drawn[i] = slots_[i].representation.get();
    DynamicOptions o = options_.dynamic;
    o.trace = nullptr;
    // The same world footprint as the full image's points: a low-resolution pixel is
    // `divisor` full ones, and a per-pixel point's footprint is half a pixel.
    const ShadingRate rate = options_.shadingRate.value_or(scene_.settings.shadingRate);
    o.footprintScale = options_.dynamic.footprintScale * footprintPixels(rate, spp) /
                       (0.5f * static_cast<float>(divisor));
    o.shadingRate = ShadingRate::Pixel;
    o.deadline = deadline;
    predictor_->begin(predictState_, drawn, predictLayout_, o);
    // Abandoned in rasterization: no visibility to trust, so nothing predicted. In
    // shading: the finished bands' tiles stand.
    std::vector<TileRequest> lacking;
    if (!predictor_->abandoned()) lacking = predictor_->shade(true);
    predictionAbandoned_ = predictor_->abandoned();
    seconds = predictionAbandoned_ ? std::max(seconds, secondsSince(start)) : secondsSince(start);
    return lacking;
}

std::vector<TileRequest> MultiphaseRenderer::adjacentTiles() const {
    std::vector<TileRequest> out;
    for (const TileRequest& r : lastLacking_) {
        const ObjectRepresentation* rep = slots_[r.object].representation.get();
        if (!rep || !rep->map) continue;
        const ShaderMap& map = *rep->map;
        const int side = map.tilesPerSide(r.key.level);
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int tx = r.key.tx + dx, ty = r.key.ty + dy;
                if ((dx == 0 && dy == 0) || tx < 0 || ty < 0 || tx >= side || ty >= side) continue;
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
    const PausedFiller paused(*this);  // room in the cache is this loop's alone
    const std::vector<const ObjectRepresentation*> maps = representations();
    // A guess never displaces a tile in the cache: only room left is used.
    FillLimits limits = fillLimits(CacheRoom::RoomLeft, stats.index);
    limits.trace = nullptr;
    limits.deadline =
        start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
    TileFillResult fills;
    tiles_.fill(tiles, maps, limits, fills);
    for (const TileRequest& r : fills.filled) {
        const ShaderMap* map = maps[r.object]->map.get();
        const int slot = map->slotOf(r.key);
        if (slot >= 0) prefetched_.push_back({r.object, map, r.key, slot, useStamp_});
    }
    stats.tilesPrefetched += fills.costs.tilesFilled;
    return secondsSince(start);
}

void MultiphaseRenderer::settlePrefetched(FrameStats& stats) {
    const auto start = Clock::now();
    size_t kept = 0;
    for (const Prefetched& p : prefetched_) {
        const ObjectRepresentation* rep = slots_[p.object].representation.get();
        // Dropped, or its map replaced by a new static run, before any probe read it.
        const bool gone = !rep || rep->map.get() != p.map || p.map->slotOf(p.key) != p.slot;
        if (gone) {
            ++stats.prefetchWasted;
        } else if (p.map->pool()->lastUse(p.slot) == useStamp_) {
            // This frame's probes read it (a prediction's probes, run later in a frame,
            // leave an older stamp by the next frame's settling).
            ++stats.prefetchUsed;
        } else if (useStamp_ - p.stamp >= static_cast<uint32_t>(options_.prefetchPatienceFrames)) {
            ++stats.prefetchWasted;
        } else {
            prefetched_[kept++] = p;
        }
    }
    prefetched_.resize(kept);
    stats.controllerSeconds += secondsSince(start);
}

}  // namespace mpshade
