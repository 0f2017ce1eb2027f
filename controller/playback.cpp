#include "controller/playback.h"

#include <chrono>
#include <cmath>

#include "controller/tile_predictor.h"
#include "geometry/error.h"

namespace mpshade {

PlaybackSummary playScene(const Scene& scene, const PlaybackOptions& options,
                          const PlaybackFrameFn& onFrame,
                          const std::function<void(const PlaybackSummary&)>& onPreroll) {
    MPSHADE_CHECK(options.fps > 0.0);
    MultiphaseOptions mo;
    // The always-resident levels are filled as each map is made: a missing tile always has
    // a coarser level to fall back on.
    mo.staticPhase.shaderMap.fillPinnedUpFront = true;
    mo.singlePhaseFrames = false;  // the reference renderer cannot keep a frame rate
    mo.mapMemoryBytes = options.cacheBytes;
    mo.backgroundFills = options.backgroundFills;
    mo.backgroundDuringFrames = options.backgroundDuringFrames;
    mo.trace = options.trace;
    MultiphaseRenderer renderer(scene, mo);
    renderer.plan(options.first, options.last, options.render);
    PlaybackSummary summary;
    if (options.first >= options.last) return summary;
    const auto start = std::chrono::steady_clock::now();
    // The pre-roll has all the time it needs, but not more memory than the cache: its fills
    // go through the budgeted path, which stops when the cache is full.
    renderer.setFrameBudget(1e9);
    const int spp = options.render.samplesPerPixel > 0 ? options.render.samplesPerPixel
                                                       : scene.settings.samplesPerPixel;
    renderer.setShadingRate(scene.settings.shadingRate);  // the regulator's top step
    FrameStats preroll;
    Image image;  // reused frame to frame
    renderer.renderFrame(options.first, options.render, preroll, image);
    // The regulator's ratios: the first frame again at every step, now warm (its objects
    // built, its buffers allocated); each also fills what its own step reads.
    QualityRegulator regulator(scene.settings.shadingRate, spp, options.regulator);
    // The request's render options with a step's samples per pixel.
    const auto stepOptions = [&](int level) {
        RenderOptions r = options.render;
        if (regulator.step(level).samplesPerPixel > 0)
            r.samplesPerPixel = regulator.step(level).samplesPerPixel;
        return r;
    };
    std::vector<double> stepSeconds(static_cast<size_t>(regulator.levels()));
    for (int k = 0; k < regulator.levels(); ++k) {
        renderer.setShadingRate(regulator.step(k).rate);
        renderer.setFootprintScale(regulator.step(k).footprintScale);
        FrameStats s;
        renderer.renderFrame(options.first, stepOptions(k), s, image);
        stepSeconds[static_cast<size_t>(k)] = s.dynamic.seconds();
        summary.steps.push_back({regulator.step(k), stepSeconds[static_cast<size_t>(k)], 0});
    }
    const double budget = 1.0 / options.fps;
    regulator.calibrate(stepSeconds, budget);
    renderer.setShadingRate(regulator.step().rate);
    renderer.setFootprintScale(regulator.step().footprintScale);
    // Warming the cache for the first frames, at the step they start on: the tiles of
    // every third frame of the first prerollPrefetchSeconds, predicted at half the size,
    // filled as far as the cache allows. Then one prediction as the frames make them, so
    // the first frames know what one costs.
    TilePredictor predictor(renderer);
    double predictCost = 0.0;  // the last prediction's seconds
    int framesWithoutPrediction = 0;
    if (options.prefetch) {
        const int ahead =
            static_cast<int>(std::lround(options.prerollPrefetchSeconds * scene.settings.fps));
        std::vector<TileRequest> tiles;
        for (int f = options.first + 1; f <= std::min(options.last - 1, options.first + ahead);
             f += 3) {
            std::vector<TileRequest> more =
                predictor.predict(f, stepOptions(regulator.level()), 2, predictCost);
            tiles.insert(tiles.end(), more.begin(), more.end());
        }
        FrameStats warm;
        renderer.prefetch(tiles, options.prerollPrefetchWallSeconds, warm);
        predictor.predict(options.first, stepOptions(regulator.level()), options.predictDivisor,
                          predictCost);
    }
    summary.prerollSeconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (onPreroll) onPreroll(summary);
    renderer.setFrameBudget(budget);
    for (int frame = options.first; frame < options.last; ++frame) {
        const PlaybackQuality quality{regulator.level(), regulator.step()};
        renderer.setShadingRate(quality.step.rate);
        renderer.setFootprintScale(quality.step.footprintScale);
        FrameStats stats;
        renderer.renderFrame(frame, stepOptions(quality.level), stats, image);
        // The twentieth of the budget kept for the end of the frame, as fills keep it.
        const double slack = 0.95 * budget - stats.wallSeconds;
        if (options.lookAheadSeconds > 0.0 && slack > 0.0) {
            const int frames =
                static_cast<int>(std::ceil(options.lookAheadSeconds * scene.settings.fps));
            const double spent =
                renderer.buildAhead(frame, frames, options.render, slack, stats.budget.builtAhead);
            stats.staticWork.seconds += spent;
            stats.wallSeconds += spent;
            stats.budget.deadlineMet = stats.wallSeconds <= budget;
        }
        // Only once the frame's own tiles are all in, within the twentieth of the budget
        // kept for the end of the frame.
        const double slackLeft = 0.95 * budget - stats.wallSeconds;
        const bool retry =
            framesWithoutPrediction >= options.predictRetryFrames && slackLeft > 0.5 * predictCost;
        ++framesWithoutPrediction;
        if (options.prefetch && stats.budget.tilesDeferred == 0 &&
            (slackLeft > predictCost || retry)) {
            framesWithoutPrediction = 0;
            // A prediction runs longer than its last at times (twice as long, when the
            // machine is busy elsewhere): one still running at the end of the slack is
            // abandoned rather than making the frame late.
            const auto deadline = std::chrono::steady_clock::now() +
                                  std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                      std::chrono::duration<double>(slackLeft));
            const int ahead =
                std::min(options.last - 1,
                         frame + std::max(1, static_cast<int>(std::lround(options.predictSeconds *
                                                                          scene.settings.fps))));
            const auto predicting = std::chrono::steady_clock::now();
            std::vector<TileRequest> tiles = predictor.predict(
                ahead, options.render, options.predictDivisor, predictCost, deadline);
            const double predicted =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - predicting)
                    .count();
            stats.prefetch.abandoned = predictor.abandoned();
            stats.prefetch.predicted = tiles.size();
            const std::vector<TileRequest> adjacent = renderer.adjacentTiles();
            stats.prefetch.adjacent = adjacent.size();
            tiles.insert(tiles.end(), adjacent.begin(), adjacent.end());
            const double spent = predicted + renderer.prefetch(tiles, slackLeft - predicted, stats);
            stats.prefetch.seconds = spent;
            stats.staticWork.seconds += spent;
            stats.wallSeconds += spent;
            stats.budget.deadlineMet = stats.wallSeconds <= budget;
        }
        ++summary.frames;
        summary.deadlinesMet += stats.budget.deadlineMet ? 1 : 0;
        ++summary.steps[static_cast<size_t>(quality.level)].frames;
        const auto regulating = std::chrono::steady_clock::now();
        regulator.update(stats, budget);
        stats.controllerSeconds +=
            std::chrono::duration<double>(std::chrono::steady_clock::now() - regulating).count();
        if (onFrame && !onFrame(stats, image, quality)) break;
    }
    return summary;
}

}  // namespace mpshade
