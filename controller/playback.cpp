#include "controller/playback.h"

#include <chrono>
#include <cmath>

#include "geometry/error.h"

namespace mpshade {

PlaybackSummary playScene(const Scene& scene, const PlaybackOptions& options,
                          const PlaybackFrameFn& onFrame,
                          const std::function<void(double)>& onPreroll) {
    MPSHADE_CHECK(options.fps > 0.0);
    MultiphaseOptions mo;
    // The always-resident levels are filled as each map is made: a missing tile always has
    // a coarser level to fall back on.
    mo.staticPhase.shaderMap.fillPinnedUpFront = true;
    mo.singlePhaseFrames = false;  // the reference renderer cannot keep a frame rate
    mo.mapMemoryBytes = options.cacheBytes;
    mo.trace = options.trace;
    MultiphaseRenderer renderer(scene, mo);
    renderer.plan(options.first, options.last, options.render);
    PlaybackSummary summary;
    if (options.first >= options.last) return summary;
    const auto start = std::chrono::steady_clock::now();
    // The pre-roll has all the time it needs, but not more memory than the cache: its fills
    // go through the budgeted path, which stops when the cache is full.
    renderer.setFrameBudget(1e9);
    FrameStats preroll;
    renderer.renderSamples(options.first, options.render, preroll);
    summary.prerollSeconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (onPreroll) onPreroll(summary.prerollSeconds);
    const double budget = 1.0 / options.fps;
    renderer.setFrameBudget(budget);
    // The shading-rate regulator: per pixel once the dynamic phase takes most of the
    // budget, per sample again once it takes little of it (hysteresis between the two, so
    // it does not flicker frame to frame).
    ShadingRate rate = scene.settings.shadingRate;
    for (int frame = options.first; frame < options.last; ++frame) {
        renderer.setShadingRate(rate);
        FrameStats stats;
        const Image image = renderer.renderFrame(frame, options.render, stats);
        const double slack = budget - stats.wallSeconds;
        if (options.lookAheadSeconds > 0.0 && slack > 0.0) {
            const int frames =
                static_cast<int>(std::ceil(options.lookAheadSeconds * scene.settings.fps));
            const double spent =
                renderer.buildAhead(frame, frames, options.render, slack, stats.builtAhead);
            stats.staticSeconds += spent;
            stats.wallSeconds += spent;
            stats.deadlineMet = stats.wallSeconds <= budget;
        }
        ++summary.frames;
        summary.deadlinesMet += stats.deadlineMet ? 1 : 0;
        if (onFrame && !onFrame(stats, image, rate)) break;
        const double dynamic =
            stats.warpSeconds + stats.rasterSeconds + stats.shadeSeconds + stats.resolveSeconds;
        if (rate == ShadingRate::Sample && dynamic > options.slowDownAt * budget)
            rate = ShadingRate::Pixel;
        else if (rate == ShadingRate::Pixel && scene.settings.shadingRate == ShadingRate::Sample &&
                 dynamic < options.speedUpAt * budget)
            rate = ShadingRate::Sample;
    }
    return summary;
}

}  // namespace mpshade
