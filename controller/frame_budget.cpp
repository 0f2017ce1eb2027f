// frame_budget.cpp -- MultiphaseRenderer's mechanisms for a locked frame rate
// (MultiphaseOptions::frameBudgetSeconds; the policy that drives them is
// controller/playback.h): the lacking tiles filled in the time left of a frame, and
// objects built ahead of the frames that will see them.
#include <algorithm>
#include <chrono>

#include "controller/fill_pacer.h"
#include "controller/multiphase_renderer.h"

namespace mpshade {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

double MultiphaseRenderer::buildAhead(int frame, int frames, const RenderOptions& options,
                                      double seconds, int& built) {
    const auto start = Clock::now();
    built = 0;
    const PausedFiller paused(*this);
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
            // Half as much again, as rebuilds are admitted: an estimate, not a measure.
            if (secondsSince(start) + 1.5 * cost > seconds) continue;
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
    const PausedFiller paused(*this);  // the cache's budget is this loop's alone
    stats.controllerSeconds += paused.seconds;
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
    size_t next = 0;
    FillPacer pacer(tileSeconds_);
    // A twentieth of the budget is kept for what follows the fills. A frame already late
    // gets its minimum share; one that is not is never made late by fills.
    const double budget = options_.frameBudgetSeconds, elapsed = secondsSince(start);
    const double deadline =
        elapsed < 0.95 * budget ? 0.95 * budget : elapsed + options_.minimumStaticShare * budget;
    while (next < lacking_.size()) {
        const size_t chunk = pacer.chunk(deadline - secondsSince(start));
        if (chunk == 0) break;
        const size_t end = std::min(lacking_.size(), next + chunk);
        const std::span<const TileRequest> batch(lacking_.data() + next, end - next);
        size_t incoming = 0;
        for (const TileRequest& r : batch) incoming += drawn_[r.object]->map->tileBytes();
        // Locked frame rate: the cache's budget holds (what does not fit waits, the frame
        // reads coarser levels); constant quality fills what its frame needs regardless.
        if (!keepMapsInBudget(incoming, stats)) break;
        const auto began = Clock::now();
        static_.fill(batch, drawn_, fills, &timing);
        pacer.filled(secondsSince(began), batch.size());
        for (const TileRequest& r : batch) ++reports_[r.object].staticCosts.tilesFilled;
        next = end;
    }
    tileSeconds_ = pacer.remembered();
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
    recordResidency(stats);
    if (options_.backgroundFills && next < lacking_.size()) {
        if (!filler_)
            filler_ = std::make_unique<BackgroundFiller>(
                static_.tilePools(), options_.mapMemoryBytes, options_.backgroundIdlePriority);
        std::vector<BackgroundJob> jobs;
        const size_t end = std::min(lacking_.size(), next + options_.backgroundQueue);
        jobs.reserve(end - next);
        for (size_t k = next; k < end; ++k)
            jobs.push_back({lacking_[k].object, drawn_[lacking_[k].object]->map, lacking_[k].key});
        filler_->submit(std::move(jobs));
    }
    lastLacking_.swap(lacking_);
    lacking_.clear();
}

}  // namespace mpshade
