#include "controller/playback.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "controller/tile_predictor.h"
#include "geometry/error.h"
#include "shadermaps/tile_store.h"

namespace mpshade {
namespace {

using Clock = std::chrono::steady_clock;

// The request's render options at a quality step: its shading rate and footprint scale,
// and with `withSamples` its samples per pixel where the step sets them.
RenderOptions atStep(const RenderOptions& render, const QualityStep& step, bool withSamples) {
    RenderOptions r = render;
    r.shadingRate = step.rate;
    r.footprintScale = step.footprintScale;
    if (withSamples && step.samplesPerPixel > 0) r.samplesPerPixel = step.samplesPerPixel;
    return r;
}

}  // namespace

std::vector<RefineStep> refineStepsAbove(const QualityRegulator& regulator, int level) {
    const QualityStep& base = regulator.step(level);
    const RefineStep own{base.rate, base.footprintScale};
    std::vector<RefineStep> steps;
    for (int k = level - 1; k >= 0; --k) {
        const QualityStep& q = regulator.step(k);
        const RefineStep step{q.rate, q.footprintScale};
        if (step == own || (k > 0 && regulator.step(k - 1).rate == q.rate)) continue;
        if (std::find(steps.begin(), steps.end(), step) == steps.end()) steps.push_back(step);
    }
    return steps;
}

QualityRegulatorOptions playbackRegulatorOptions(const PlaybackOptions& options) {
    QualityRegulatorOptions r = options.regulator;
    // Refining, the step is chosen for the cheap pass alone, within a share of the budget.
    if (options.refine.enabled) {
        r.refinedShare = options.refine.baseShare;
        r.slowDownAt = options.refine.slowDownAt;
    }
    return r;
}

namespace {

// One playback: the renderer, its regulator and predictor, and the steps of the pre-roll
// and of each frame.
class Player {
  public:
    Player(const Scene& scene, const PlaybackOptions& options)
        : scene_(scene),
          options_(options),
          renderer_(scene, rendererOptions(options)),
          regulator_(scene.settings.shadingRate,
                     options.render.resolved(scene.settings).samplesPerPixel,
                     playbackRegulatorOptions(options)),
          predictor_(renderer_),
          budget_(1.0 / options.fps) {
        // Packs written by the store's own thread, not inside the frames' fills.
        if (options.store) options.store->setWriteBehind(true);
        renderer_.plan(options.first, options.last, options.render);
    }

    // Before the clock: the first frame at the scene's own shading rate as far as the cache
    // allows (the pre-roll has all the time it needs, but not more memory than the cache:
    // its fills go through the budgeted path, which stops when the cache is full), the
    // regulator calibrated, and the cache warmed.
    void preroll(PlaybackSummary& summary) {
        // Built at the first occlusion ray otherwise: in a frame whose fill traces it, when
        // the pre-roll's tiles all came from the store.
        renderer_.resources().buildRayScenes();
        RenderOptions first = options_.render;
        first.shadingRate = scene_.settings.shadingRate;  // the regulator's top step
        FrameStats stats;
        // The footprints measured on the first frame at constant quality, as a render from it
        // measures them (each tile it reads filled: a fallback would skew the measure).
        if (options_.footprints.enabled) {
            renderer_.renderFrame(options_.first, first, stats, image_);
            if (stats.footprintCalibration.objects > 0)
                for (size_t i = 0; i < scene_.objects.size(); ++i)
                    summary.objectFootprints.push_back(renderer_.report(i).footprintScale);
        }
        renderer_.setFrameBudget(1e9);
        renderer_.renderFrame(options_.first, first, stats, image_);
        calibrate(summary);
        if (options_.refine.enabled && regulator_.level() > 0) {
            // The first frame refined once before the clock: refinement's buffers made, its
            // error per unit of contrast and its resolve's time measured, and the tiles its
            // finer footprints read filled (the first played frame had run late without).
            renderer_.setRefineSteps(betterSteps(regulator_.level()));
            renderer_.renderFrame(options_.first, atStep(options_.render, regulator_.step(), true),
                                  stats, image_);
        }
        if (options_.prefetch) warmCache();
        renderer_.setFrameBudget(budget_);
    }

    // One frame within its budget, then what its slack allows: building ahead, predicting
    // and prefetching. Returns the frame's stats and the quality it played at.
    FrameStats play(int frame, PlaybackQuality& quality) {
        quality = {regulator_.level(), regulator_.step()};
        if (options_.refine.enabled) renderer_.setRefineSteps(betterSteps(quality.level));
        FrameStats stats;
        renderer_.renderFrame(frame, atStep(options_.render, quality.step, true), stats, image_);
        // The twentieth of the budget kept for the end of the frame, as fills keep it.
        const double slack = 0.95 * budget_ - stats.wallSeconds;
        if (options_.lookAheadSeconds > 0.0 && slack > 0.0)
            buildAhead(frame, quality, slack, stats);
        prefetchAhead(frame, quality, stats);
        const auto regulating = Clock::now();
        regulator_.update(stats, budget_);
        stats.controllerSeconds += secondsSince(regulating);
        return stats;
    }

    const Image& image() const { return image_; }

  private:
    // Per pixel at footprint x2 refines to per pixel, then per sample (on the courtyard,
    // against per sample alone: 35.4 and 35.4 dB median against 35.3 and 34.5,
    // docs/playback.md).
    std::vector<RefineStep> betterSteps(int level) const {
        return refineStepsAbove(regulator_, level);
    }

    static MultiphaseOptions rendererOptions(const PlaybackOptions& options) {
        MultiphaseOptions mo;
        // The always-resident levels are filled as each map is made: a missing tile always
        // has a coarser level to fall back on.
        mo.staticPhase.shaderMap.fillPinnedUpFront = true;
        mo.singlePhaseFrames = false;  // the reference renderer cannot keep a frame rate
        mo.mapMemoryBytes = options.cacheBytes;
        mo.backgroundFills = options.backgroundFills;
        mo.backgroundDuringFrames = options.backgroundDuringFrames;
        mo.backgroundRebuilds = options.backgroundRebuilds;
        mo.trace = options.trace;
        mo.staticPhase.store = options.store;
        mo.refine = options.refine;
        mo.footprints = options.footprints;
        return mo;
    }

    // The regulator's ratios: the first frame again at every step, now warm (its objects
    // built, its buffers allocated), calibrationFrames times, the least kept; each also
    // fills what its own step reads. Each shades afresh: the same view again would
    // otherwise run on the inputs the last one kept. A
    // step whose probes fell back (a coarser footprint reads levels no step before it had
    // filled) is measured again once they are filled: the fallbacks' slower path had priced
    // per pixel at 1280x720 (teapot) at 36-38 ms and per pixel at twice the footprint above
    // per 2x2 pixels, 44 ms against 24.
    void calibrate(PlaybackSummary& summary) {
        std::vector<double> stepSeconds(static_cast<size_t>(regulator_.levels()));
        for (int k = 0; k < regulator_.levels(); ++k) {
            RenderOptions fresh = atStep(options_.render, regulator_.step(k), true);
            fresh.reuseStillView = false;
            PlaybackStep step;
            step.step = regulator_.step(k);
            for (int m = 0; m < std::max(1, options_.calibrationFrames); ++m) {
                FrameStats s;
                renderer_.renderFrame(options_.first, fresh, s, image_);
                if (m == 0 && s.dynamic.probeFallbacks > 0)
                    renderer_.renderFrame(options_.first, fresh, s, image_);
                step.probeFallbacks = std::max(step.probeFallbacks, s.dynamic.probeFallbacks);
                step.measuredSeconds.push_back(s.dynamic.seconds());
            }
            step.dynamicSeconds = stepSeconds[static_cast<size_t>(k)] =
                *std::min_element(step.measuredSeconds.begin(), step.measuredSeconds.end());
            summary.steps.push_back(std::move(step));
        }
        regulator_.calibrate(stepSeconds, budget_);
    }

    // Warming the cache for the first frames, at the step they start on: the tiles of every
    // third frame of the first prerollPrefetchSeconds, predicted at half the size, filled as
    // far as the cache allows. Then one prediction as the frames make them, so the first
    // frames know what one costs.
    void warmCache() {
        const RenderOptions step = atStep(options_.render, regulator_.step(), true);
        const int ahead =
            static_cast<int>(std::lround(options_.prerollPrefetchSeconds * scene_.settings.fps));
        std::vector<TileRequest> tiles;
        for (int f = options_.first + 1; f <= std::min(options_.last - 1, options_.first + ahead);
             f += 3) {
            std::vector<TileRequest> more = predictor_.predict(f, step, 2, predictCost_);
            tiles.insert(tiles.end(), more.begin(), more.end());
        }
        FrameStats warm;
        renderer_.prefetch(tiles, options_.prerollPrefetchWallSeconds, warm);
        predictor_.predict(options_.first, step, options_.predictDivisor, predictCost_);
    }

    // Objects the next lookAheadSeconds will see, built in the frame's slack.
    void buildAhead(int frame, const PlaybackQuality& quality, double slack, FrameStats& stats) {
        const int frames =
            static_cast<int>(std::ceil(options_.lookAheadSeconds * scene_.settings.fps));
        const double spent =
            renderer_.buildAhead(frame, frames, atStep(options_.render, quality.step, false), slack,
                                 stats.budget.builtAhead);
        addSlackWork(spent, stats);
    }

    // Only once the frame's own tiles are all in, within the twentieth of the budget kept
    // for the end of the frame: the tiles predicted for predictSeconds ahead and those next
    // to the tiles this frame found missing, filled in what is left.
    void prefetchAhead(int frame, const PlaybackQuality& quality, FrameStats& stats) {
        const double slackLeft = 0.95 * budget_ - stats.wallSeconds;
        const bool retry = framesWithoutPrediction_ >= options_.predictRetryFrames &&
                           slackLeft > 0.5 * predictCost_;
        ++framesWithoutPrediction_;
        if (!options_.prefetch || stats.budget.tilesDeferred != 0 ||
            !(slackLeft > predictCost_ || retry))
            return;
        framesWithoutPrediction_ = 0;
        // A prediction runs longer than its last at times (twice as long, when the machine
        // is busy elsewhere): one still running at the end of the slack is abandoned rather
        // than making the frame late.
        const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                 std::chrono::duration<double>(slackLeft));
        const int ahead =
            std::min(options_.last - 1,
                     frame + std::max(1, static_cast<int>(std::lround(options_.predictSeconds *
                                                                      scene_.settings.fps))));
        const auto predicting = Clock::now();
        std::vector<TileRequest> tiles =
            predictor_.predict(ahead, atStep(options_.render, quality.step, false),
                               options_.predictDivisor, predictCost_, deadline);
        const double predicted = secondsSince(predicting);
        stats.prefetch.abandoned = predictor_.abandoned();
        stats.prefetch.predicted = tiles.size();
        const std::vector<TileRequest> adjacent = renderer_.adjacentTiles();
        stats.prefetch.adjacent = adjacent.size();
        tiles.insert(tiles.end(), adjacent.begin(), adjacent.end());
        const double spent = predicted + renderer_.prefetch(tiles, slackLeft - predicted, stats);
        stats.prefetch.seconds = spent;
        addSlackWork(spent, stats);
    }

    // Static work done in the frame's slack is the frame's.
    void addSlackWork(double seconds, FrameStats& stats) const {
        stats.staticWork.seconds += seconds;
        stats.wallSeconds += seconds;
        stats.budget.deadlineMet = stats.wallSeconds <= budget_;
    }

    const Scene& scene_;
    const PlaybackOptions& options_;
    MultiphaseRenderer renderer_;
    QualityRegulator regulator_;
    TilePredictor predictor_;
    const double budget_;
    double predictCost_ = 0.0;  // the last prediction's seconds
    int framesWithoutPrediction_ = 0;
    Image image_;  // reused frame to frame
};

}  // namespace

PlaybackSummary playScene(const Scene& scene, const PlaybackOptions& options,
                          const PlaybackFrameFn& onFrame,
                          const std::function<void(const PlaybackSummary&)>& onPreroll) {
    MPSHADE_CHECK(options.fps > 0.0);
    PlaybackSummary summary;
    Player player(scene, options);
    if (options.first >= options.last) return summary;
    const auto start = Clock::now();
    player.preroll(summary);
    summary.prerollSeconds = secondsSince(start);
    if (onPreroll) onPreroll(summary);
    for (int frame = options.first; frame < options.last; ++frame) {
        PlaybackQuality quality;
        const FrameStats stats = player.play(frame, quality);
        ++summary.frames;
        summary.deadlinesMet += stats.budget.deadlineMet ? 1 : 0;
        ++summary.steps[static_cast<size_t>(quality.level)].frames;
        if (onFrame && !onFrame(stats, player.image(), quality)) break;
    }
    return summary;
}

}  // namespace mpshade
