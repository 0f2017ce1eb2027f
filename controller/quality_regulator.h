// quality_regulator.h -- what `play` gives up when the dynamic phase alone would take the
// frame's time (the patent's Applications: quality "reduced occasionally to meet the
// frame rate"; Lengyel & Snyder 1997, sec. 6: a regulator trades quality parameters for
// fixed rendering resources, measuring what each change costs).
//
// A ladder of steps, best first, each cheaper than the one above:
//   the scene's shading rate at footprint 1; per pixel; per pixel reading one mip level
//   coarser (footprint x2: a quarter of the tiles to fill); per 2x2 pixels (a quarter of the
//   shading points, and the same level as the step above); per 2x2 pixels one level coarser;
//   then that with half the samples per pixel, and with one (rasterization, compositing
//   and the resolve scale with the samples; edges lose their antialiasing).
// Coverage stays per sample on every step.
//
// After each frame the regulator steps down when the dynamic phase (warp to resolve) took
// more than `slowDownAt` of the budget on two frames in a row at one step, or more than
// `dropAt` on one (a single frame over the share is often the machine), and steps up after
// `calmFrames` frames in a row whose dynamic phase, times the step above's cost ratio,
// would take less than `speedUpAt`, or tries the step above after `probeFrames` calm frames
// predicting it under `dropAt` (to measure its ratio again). The ratios are measured: all of them
// before the first frame (calibrate: one view rendered at every step), then each again whenever two
// consecutive frames ran on neighbouring steps. The gap between the two shares and the wait keep it
// from flickering between steps. A frame on a still view's kept inputs (view_reuse.h) costs a
// fraction of one shaded afresh: it measures no ratio against a fresh one, and the step
// above, whose first frame shades afresh, is predicted from the last fresh frame.
#pragma once

#include <span>
#include <vector>

#include "phases/frame_stats.h"
#include "scene/scene.h"

namespace mpshade {

struct QualityStep {
    ShadingRate rate = ShadingRate::Sample;
    float footprintScale = 1.0f;  // DynamicOptions::footprintScale
    int samplesPerPixel = 0;      // 0: the request's
};

struct QualityRegulatorOptions {
    double slowDownAt = 0.7;  // of the budget: two frames in a row above it step down
    double dropAt = 0.9;      // of the budget: one frame above it steps down
    double speedUpAt = 0.65;  // of the budget: the step above, predicted below it, steps up
    int calmFrames = 8;       // frames in a row that must predict so before stepping up
    // Frames in a row, calm, whose step above is predicted over speedUpAt but under dropAt,
    // after which that step is tried once: its cost ratio is measured again. A ratio
    // measured across a step down is taken on the slow frame that caused it, so it can
    // overstate the step above for good (a teapot run stayed a mip level coarser for 45 of
    // 48 frames); predicted under dropAt, the frame tried is on time either way.
    int probeFrames = 16;
    // The shares above, for the steps that are refined by tile afterwards (tile_refiner.h),
    // are times this: a frame there is shaded at its step within this part of what it would
    // otherwise get, and the rest is refinement's. The best step (nothing to refine) and the
    // cheapest with the request's samples per pixel (what is left below it has fewer
    // samples, which refinement cannot add) keep the whole shares. 1: not refining.
    double refinedShare = 1.0;
};

class QualityRegulator {
  public:
    // sceneRate: the top step's rate (the scene's); spp: samples per pixel (the shading
    // point ratio between per-sample and per-pixel shading, before anything is measured).
    QualityRegulator(ShadingRate sceneRate, int spp, const QualityRegulatorOptions& options = {});

    const QualityStep& step() const { return steps_[current_]; }
    const QualityStep& step(int level) const { return steps_[level]; }
    int level() const { return current_; }  // 0: full quality
    int levels() const { return static_cast<int>(steps_.size()); }

    // Before the first frame: `dynamicSeconds[k]`, one view's dynamic phase at step k (every
    // step, warm: its tiles resident). Takes the ratios between neighbouring steps from them
    // and starts at the best step within the middle of the two shares.
    void calibrate(std::span<const double> dynamicSeconds, double budget);

    // After a frame rendered at step(), with `budget` seconds: moves the step for the next.
    void update(const FrameStats& stats, double budget);

    // The dynamic phase at step level - 1 over that at `level` (>= 1), as last measured.
    double costRatioAbove(int level) const { return ratioAbove_[level]; }

  private:
    double share(int level) const;  // QualityRegulatorOptions::refinedShare, where it applies

    std::vector<QualityStep> steps_;
    int lastFullSamples_ = 0;         // the last step at the request's samples per pixel
    std::vector<double> ratioAbove_;  // per level >= 1
    QualityRegulatorOptions options_;
    int current_ = 0;
    int calm_ = 0;
    int probeCalm_ = 0;   // frames in a row eligible for trying the step above
    int lastLevel_ = -1;  // the previous frame's, its dynamic seconds, whether it reused its view
    double lastDynamic_ = 0.0;
    bool lastReused_ = false;
    int freshLevel_ = -1;  // the last frame that shaded afresh (DynamicFrameStats::viewReused)
    double freshDynamic_ = 0.0;
};

}  // namespace mpshade
