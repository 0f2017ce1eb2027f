// frame_budget.cpp -- MultiphaseRenderer's mechanisms for a locked frame rate
// (MultiphaseOptions::frameBudgetSeconds; the policy that drives them is
// controller/playback.h): the missing tiles filled in the time left of a frame, and
// objects built ahead of the frames that will see them.
#include <algorithm>
#include <chrono>

#include "controller/multiphase_renderer.h"

namespace mpshade {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

double MultiphaseRenderer::buildAhead(int frame, int frames, const RenderOptions& options,
                                      double seconds, int& built) {
    const auto start = Clock::now();
    built = 0;
    const BackgroundFiller::Hold paused(filler_.get(), useStamp_);
    const size_t n = slots_.size();
    const int last = std::min(scene_.frameCount() - 1, frame + frames);
    const DynamicOptions dynamic = dynamicOptionsFor(options);
    const RenderOptions resolved = options.resolved(scene_.settings);
    std::vector<uint8_t> planned(n, 0);
    for (int f = frame + 1; f <= last; ++f) {
        const FrameState ahead =
            frameStateAt(resources_, f, resolved.width, resolved.height, resolved.samplesPerPixel);
        for (size_t i = 0; i < n; ++i) {
            ObjectSlot& slot = slots_[i];
            if (slot.representation || planned[i] ||
                !objectInView(*scene_.objects[i].surface, ahead.objects[i], ahead.camera))
                continue;
            planned[i] = 1;
            ObjectCostInputs in;
            const Representation kind =
                planner_.choose(i, slot, f, ahead.objects[i], ahead.camera, ahead.spp, dynamic, in);
            const RepresentationChoice estimate = chooseRepresentation(in, options_.costModel);
            const double cost = kind == Representation::Facets      ? estimate.facetsStaticSeconds
                                : kind == Representation::ShaderMap ? estimate.mapStaticSeconds
                                                                    : 0.0;
            // Half as much again, as rebuilds are admitted: an estimate, not a measure.
            if (secondsSince(start) + 1.5 * cost > seconds) continue;
            const ScopedSpan span(options_.trace, "build ahead", PhaseKind::Static,
                                  SpanLevel::Phase, static_cast<int64_t>(i), frame);
            StaticCosts costs;
            const BuildView view =
                buildView(i, f, ahead.objects[i], ahead.camera, ahead.uniforms[i]);
            slot.representation =
                static_.build(i, kind, view.state, view.camera, view.uniforms, nullptr, costs);
            recordBuild(i, kind, costs, ahead.uniforms[i]);
            ++built;
            if (secondsSince(start) >= seconds) return secondsSince(start);
        }
    }
    return secondsSince(start);
}

void MultiphaseRenderer::fillWithinBudget(Clock::time_point start, FrameStats& stats) {
    if (missing_.empty()) {
        lastMissing_.clear();
        return;
    }
    const BackgroundFiller::Hold paused(filler_.get(),
                                        useStamp_);  // the cache's budget is this loop's alone
    stats.controllerSeconds += paused.seconds();
    orderCoarsestFirst(missing_);
    const double end = budgetedFillEnd(secondsSince(start), options_.frameBudgetSeconds,
                                       options_.minimumStaticShare);
    FillLimits limits = fillLimits(CacheRoom::EvictWithin, stats.index);
    limits.deadline =
        start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(end));
    TileFillResult fills;
    tiles_.fill(missing_, drawn_, limits, fills);
    countFills(fills, stats);
    stats.budget.tilesDeferred = missing_.size() - fills.consumed;
    recordResidency(static_.tilePools(), stats);
    if (options_.backgroundFills && fills.consumed < missing_.size())
        queueForBackground(fills.consumed);
    lastMissing_.swap(missing_);
    missing_.clear();
}

void MultiphaseRenderer::refineWithinBudget(Clock::time_point start, Image& image,
                                            FrameStats& stats) {
    if (!dynamic_.complete() || dynamic_.abandoned() || refineSteps_.empty()) return;
    // Room left for the resolve and the accounting that follow, which cover the pixels
    // near the tiles refined: the share of the time left that they took the last time
    // (refining tiles in the rest of it, the two grow together), and at least as long as
    // the whole image's resolve, for a pass slower than the last (the courtyard at 640x360
    // missed 1 of 24 deadlines without it). Twice the whole image's resolve, before the
    // resolve again covered only the tiles refined, had left 1280x720 frames nothing to
    // refine.
    const double end = options_.refine.until * options_.frameBudgetSeconds;
    const double left = std::max(0.0, end - secondsSince(start));
    const double until =
        end - std::max(refiner_.finishShare() * left, dynamic_.stats().resolveSeconds);
    const auto deadline =
        start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(until));
    const size_t before = missing_.size();
    refiner_.refine(dynamic_, {dynamicOptions_.shadingRate, dynamicOptions_.footprintScale},
                    refineSteps_, deadline, image, stats.refine, missing_);
    if (missing_.size() > before) {
        sortUniqueTiles(missing_);
        stats.tiles.missing += missing_.size() - before;
    }
}

// The missing tiles from `from` on, for the background filler (made at the first frame
// that needs it), at most MultiphaseOptions::backgroundQueue of them.
void MultiphaseRenderer::queueForBackground(size_t from) {
    if (!filler_)
        filler_ = std::make_unique<BackgroundFiller>(static_.tilePools(), options_.mapMemoryBytes,
                                                     options_.backgroundIdlePriority);
    std::vector<BackgroundJob> jobs;
    const size_t end = std::min(missing_.size(), from + options_.backgroundQueue);
    jobs.reserve(end - from);
    for (size_t k = from; k < end; ++k)
        jobs.push_back({missing_[k].object, drawn_[missing_[k].object]->map, missing_[k].key});
    filler_->submit(std::move(jobs));
}

}  // namespace mpshade
