// playback.h -- frame-rate-locked playback (`mpshade play`; patent FIG. 2, controller 240):
// every frame gets 1 / fps seconds. The dynamic phase runs first and never waits: probes
// whose tiles are missing read the finest coarser level resident (the six coarsest levels
// of every map are filled with it, so there always is one). What is left of the frame's
// time goes to static work, by benefit per cost: the tiles the frame found missing, coarser levels
// first, then nothing more -- the rest is left for later frames (MultiphaseOptions::
// frameBudgetSeconds). An object whose static phase is due again is drawn from its last
// representation until its rebuild fits a frame's slack.
//
// Before the clock starts, the first frame is rendered at full quality as far as the cache
// allows (a player loading its scene): every object it sees is built and every tile it
// asks for filled while the tiles fit `cacheBytes`.
#pragma once

#include <functional>
#include <vector>

#include "controller/multiphase_renderer.h"
#include "controller/quality_regulator.h"
#include "controller/tile_refiner.h"

namespace mpshade {

struct PlaybackOptions {
    double fps = 30.0;        // frames per second; the budget of a frame is 1 / fps
    RenderOptions render;     // image size, samples per pixel, seed (0: the scene's)
    int first = 0, last = 0;  // frames [first, last)
    // The shader maps' tiles stay under this many bytes (least recently used out first;
    // the always-resident levels are never dropped).
    size_t cacheBytes = size_t{256} << 20;
    PhaseTrace* trace = nullptr;       // not owned; null: no spans
    std::shared_ptr<TileStore> store;  // where tiles are kept between runs; null: nowhere
    // What frames give up when the dynamic phase alone takes most of the budget: shading
    // rate, then probe footprint (quality_regulator.h).
    QualityRegulatorOptions regulator;
    // Each object's footprint measured before the clock, as `render` measures it at its first
    // frame (footprint_calibration.h), so played frames read the levels constant-quality
    // frames read. Off: every object's footprint is 1.
    FootprintCalibrationOptions footprints;
    // Each frame, once shaded at the regulator's step, refined by image tile at finer rates
    // in order of priority in the time left (tile_refiner.h); the regulator's shares are then
    // scaled by RefineOptions::baseShare. Off (`play --refine off`): the whole-frame step alone.
    RefineOptions refine = [] {
        RefineOptions r;
        r.enabled = true;
        return r;
    }();
    // Looking ahead: objects the next frames up to this many seconds of scene time will see,
    // not built yet, are built in a frame's slack (MultiphaseRenderer::buildAhead), so an
    // object entering the view is ready before its first frame. 0: no look-ahead.
    double lookAheadSeconds = 0.5;
    // Prefetching in what is left of a frame after that: the tiles of the frame this many
    // seconds of scene time ahead, predicted at 1/predictDivisor of the image each way
    // (claim 11), then those next to the tiles this frame found missing (claim 10). Off: none.
    bool prefetch = true;
    // The pre-roll also fills the tiles predicted for the frames of this many seconds of
    // scene time after the first (every third frame, at half the size), as far as the cache
    // allows and for at most prerollPrefetchWallSeconds: a player warming its cache while it
    // loads (a scene of dear static shaders would otherwise load for as long as its cache
    // takes to fill). 0: only the first frame's.
    double prerollPrefetchSeconds = 1.0;
    double prerollPrefetchWallSeconds = 2.0;
    // The pre-roll measures each step of the regulator's ladder this many times (the first
    // frame again, warm) and keeps the least: one frame's time on a busy machine can be a
    // third over its usual, and a step measured so had started the gallery one step too low
    // (docs/playback.md).
    int calibrationFrames = 2;
    double predictSeconds = 0.1;
    int predictDivisor = 4;
    // A prediction starts when the slack holds its last cost. One still running when the
    // slack ends is abandoned (the frame stays on time) and its cost kept as at least that
    // long; after this many frames without one, one starts when half its cost fits, so
    // that one slow prediction does not keep every later one away.
    int predictRetryFrames = 15;
    // Tiles a frame found missing and had no time left to fill go to a worker thread at idle
    // priority, which fills them outside the frames' dynamic phase: while the frame's image
    // is written, a prediction's probes run, and between frames (background_filler.h).
    // backgroundDuringFrames: also alongside the dynamic phase. Measured at 640x360 on 2
    // cores (docs/playback.md), that cost a frame's deadline in about one run of two.
    bool backgroundFills = true;
    bool backgroundDuringFrames = false;
    // An object whose view left its range is re-diced on a worker thread at idle priority
    // while the frames draw its last representation (background_builder.h); off: only
    // within a frame whose time left fits its expected cost.
    bool backgroundRebuilds = true;
};

// One step of the quality regulator's ladder, as the pre-roll measured it.
struct PlaybackStep {
    QualityStep step;
    double dynamicSeconds = 0.0;          // the first frame's dynamic phase at this step, warm: the
                                          // least of measuredSeconds
    std::vector<double> measuredSeconds;  // each of PlaybackOptions::calibrationFrames
    int frames = 0;                       // frames played at this step
    // Of the frame measured, the probes that fell back to a coarser level: 0 unless the
    // cache could not hold the tiles the step reads.
    uint64_t probeFallbacks = 0;
};

struct PlaybackSummary {
    double prerollSeconds = 0.0;  // the first frame at constant quality, before the clock
    int frames = 0, deadlinesMet = 0;
    std::vector<PlaybackStep> steps;  // the ladder, best first (PlaybackQuality::level)
    // Per scene object, the footprint multiplier the pre-roll measured
    // (controller/footprint_calibration.h); 1 for one not measured. Empty if none was.
    std::vector<float> objectFootprints;
};

// Plays frames [first, last); after each, onFrame(stats, image, the quality step it used)
// (its time is not the frame's: writing to disk is the caller's), which returns false to
// stop playback there.
struct PlaybackQuality {
    int level = 0;  // QualityRegulator::level(): 0 is full quality
    QualityStep step;
};
using PlaybackFrameFn =
    std::function<bool(const FrameStats&, const Image&, const PlaybackQuality&)>;
// onPreroll(summary) once the pre-roll is done, before the first frame: its seconds and
// the steps with their measured costs (no frame played yet).
PlaybackSummary playScene(const Scene& scene, const PlaybackOptions& options,
                          const PlaybackFrameFn& onFrame,
                          const std::function<void(const PlaybackSummary&)>& onPreroll = {});

// The steps a frame played at `level` of `regulator`'s ladder refines its tiles to
// (tile_refiner.h), nearest first: the ladder's steps above it as rates and footprints at
// the frame's own samples per pixel (refinement cannot add samples, so a frame at fewer
// refines its rate and footprint at them); the frame's own rate and footprint excluded, and
// of those at one rate only the best (the same points to shade, at a sharper footprint).
std::vector<RefineStep> refineStepsAbove(const QualityRegulator& regulator, int level);

// The regulator's options for a playback: options.regulator, and while refining its shares
// scaled by RefineOptions::baseShare and its step down at RefineOptions::slowDownAt.
QualityRegulatorOptions playbackRegulatorOptions(const PlaybackOptions& options);

}  // namespace mpshade
