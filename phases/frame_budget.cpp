// frame_budget.cpp -- MultiphaseRenderer's mechanisms for a locked frame rate
// (MultiphaseOptions::frameBudgetSeconds; the policy that drives them is
// controller/playback.h): the lacking tiles filled in the time left of a frame, and
// objects built ahead of the frames that will see them.
#include <algorithm>
#include <chrono>

#include <tbb/task_arena.h>

#include "phases/multiphase_renderer.h"

namespace mpshade {
namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

double MultiphaseRenderer::buildAhead(int frame, int frames, const RenderOptions& options,
                                      double seconds, int& built) {
    const auto start = Clock::now();
    built = 0;
    const size_t n = scene_.objects.size();
    const int last = std::min(scene_.frameCount() - 1, frame + frames);
    std::vector<uint8_t> planned(n, 0);
    for (int f = frame + 1; f <= last; ++f) {
        const FrameState ahead =
            frameStateAt(resources_, f, options.width, options.height, options.samplesPerPixel);
        for (size_t i = 0; i < n; ++i) {
            if (representations_[i] || planned[i] ||
                !objectInView(*scene_.objects[i].surface, ahead.objects[i], ahead.camera))
                continue;
            planned[i] = 1;
            ObjectCostInputs in;
            const Representation kind =
                chooseKind(i, f, ahead.objects[i], ahead.camera, ahead.spp, in);
            const RepresentationChoice estimate = chooseRepresentation(in, options_.costModel);
            const double cost = kind == Representation::Facets ? estimate.facetsStaticSeconds
                                                               : estimate.mapStaticSeconds;
            if (secondsSince(start) + cost > seconds) continue;
            const ScopedSpan span(options_.trace, "build ahead", PhaseKind::Static,
                                  SpanLevel::Phase, static_cast<int64_t>(i), frame);
            StaticCosts costs;
            kinds_[i] = kind;
            representations_[i] = static_.build(i, kind, ahead.objects[i], ahead.camera,
                                                ahead.uniforms[i], nullptr, costs);
            longestEdge_[i] = 0.0f;
            lastBuildSeconds_[i] = costs.seconds;
            staticInputs_[i].read(ahead.uniforms[i], builtInputs_[i]);
            ObjectReport& r = reports_[i];
            r.kind = kind;
            ++r.staticRuns;
            r.staticCosts.runs += costs.runs;
            r.staticCosts.seconds += costs.seconds;
            r.staticCosts.instructions += costs.instructions;
            r.staticCosts.tilesFilled += costs.tilesFilled;
            ++built;
            if (secondsSince(start) >= seconds) return secondsSince(start);
        }
    }
    return secondsSince(start);
}

void MultiphaseRenderer::fillWithinBudget(Clock::time_point start, FrameStats& stats) {
    if (lacking_.empty()) {
        lastLacking_.clear();
        return;
    }
    const int frame = stats.index;
    // Coarser levels first: a tile there serves four times the surface of one a level
    // finer, and (built from its children where they are resident) costs no more.
    std::stable_sort(
        lacking_.begin(), lacking_.end(),
        [](const TileRequest& a, const TileRequest& b) { return a.key.level > b.key.level; });
    StaticCosts fills;
    FillTiming timing;
    timing.trace = options_.trace;
    timing.frame = frame;
    const auto fillStart = Clock::now();
    size_t next = 0, chunk = 2;
    // Seconds a tile, the most a chunk took lately: tiles built from resident children
    // cost a fifth of those evaluated whole, so chunks are sized for the dear ones.
    double perTile = tileSeconds_;
    const size_t threads = static_cast<size_t>(tbb::this_task_arena::max_concurrency());
    // A twentieth of the budget is kept for what follows the fills; chunks are sized to
    // half the time left at the cost a tile has had lately, so one slow chunk does not
    // overshoot. A frame already late gets its minimum share; one that is not is never
    // made late by fills.
    const double budget = options_.frameBudgetSeconds, elapsed = secondsSince(start);
    const double deadline =
        elapsed < 0.95 * budget ? 0.95 * budget : elapsed + options_.minimumStaticShare * budget;
    while (next < lacking_.size()) {
        const double left = deadline - secondsSince(start);
        if (perTile > 0.0)
            chunk = static_cast<size_t>(std::clamp(0.5 * left / perTile, 0.0, 4096.0));
        // The cost per tile is measured on chunks filled by every thread: a chunk smaller
        // than the threads takes longer per tile than that, so it is not started.
        if (left <= 0.0 || chunk < (perTile > 0.0 ? threads : 1)) break;
        const size_t end = std::min(lacking_.size(), next + chunk);
        const std::span<const TileRequest> batch(lacking_.data() + next, end - next);
        size_t incoming = 0;
        for (const TileRequest& r : batch) incoming += drawn_[r.object]->map->tileBytes();
        // Locked frame rate: the cache's budget holds (what does not fit waits, the frame
        // reads coarser levels); constant quality fills what its frame needs regardless.
        if (!keepMapsInBudget(incoming, stats)) break;
        const auto began = Clock::now();
        static_.fill(batch, drawn_, fills, &timing);
        const double took = secondsSince(began);
        perTile = std::max(perTile, took / static_cast<double>(batch.size()));
        for (const TileRequest& r : batch) ++reports_[r.object].staticCosts.tilesFilled;
        next = end;
    }
    // Forgotten slowly: the next frame's chunks start from nine tenths of this one's worst.
    if (perTile > 0.0) tileSeconds_ = 0.9 * perTile;
    stats.tilesDeferred = lacking_.size() - next;
    stats.fillSeconds += secondsSince(fillStart);
    stats.staticSeconds += secondsSince(fillStart);
    if (options_.trace)
        options_.trace->span("fill", PhaseKind::Static, SpanLevel::Phase, fillStart, Clock::now(),
                             -1, frame);
    stats.staticInstructions += fills.instructions;
    stats.tilesFilled += fills.tilesFilled;
    stats.tilesFromChildren += fills.tilesFromChildren;
    stats.texelsFilled += fills.texelsFilled;
    for (size_t i = 0; i < timing.objectSeconds.size(); ++i) {
        frameStaticSeconds_[i] += timing.objectSeconds[i];
        reports_[i].staticCosts.seconds += timing.objectSeconds[i];
        reports_[i].staticCosts.instructions += timing.objectInstructions[i];
    }
    stats.residentTiles = stats.residentBytes = stats.residentPinnedBytes = 0;
    for (const auto& pool : static_.tilePools().all()) {
        stats.residentTiles += pool->tilesHeld();
        stats.residentBytes += pool->bytesHeld();
        stats.residentPinnedBytes += pool->pinnedBytesHeld();
    }
    lastLacking_.swap(lacking_);
    lacking_.clear();
}

}  // namespace mpshade
