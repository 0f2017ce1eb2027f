// tile_refiner.h -- a played frame's time spent where its image needs it (issue: refinement
// by tile under the deadline). Watson, Luebke and Dayal ("Breaking the Frame", 1997, sec. 3)
// choose which image tiles to update by a probability made of each tile's error and its
// age, each normalized over the image, so changing regions are updated more often and no
// region is starved; the patent's controller trades quality for a frame rate (col. 11).
//
// Here a frame is first shaded at the regulator's step (quality_regulator.h) and resolved;
// then image tiles are shaded again at the better steps of the ladder (a finer rate, a
// sharper footprint: per pixel at footprint x2 -> per pixel -> per sample), one pass per
// step, in order of priority, until the refinement's deadline (DynamicPhase::refine: the
// tiles done are always a prefix). The samples of a refined tile are exactly those of a
// frame shaded at its step; the resolve's filter, run again over the whole image, blends
// tiles of different steps without seams.
//
// A tile's priority, from what the frame already has:
//   error  its contrast in the cheap image (the squared RGB differences between
//          neighbouring pixels, which 2x2 or per-pixel shading smooths away at texture,
//          highlights and edges) times the error per unit of contrast that refinement
//          measured (the squared change it made in the tiles it refined, over their
//          contrast: a running ratio), plus Watson's temporal error (the squared change of
//          the tile's mean colour since the last frame) times temporalWeight;
//   age    frames since it was last refined to the best step.
// p = errorWeight * error / sum(error) + ageWeight * age / sum(age); a tile refined in the
// last frame gets p * (1 + hysteresis), so the boundary between refined and cheap tiles
// does not flicker between frames of nearly one view.
#pragma once

#include <chrono>
#include <span>
#include <vector>

#include "phases/dynamic_phase.h"
#include "phases/frame_stats.h"

namespace mpshade {

struct RefineOptions {
    bool enabled = false;  // MultiphaseRenderer: only with a frame budget (playback turns it on)
    int tileSize = 16;     // pixels a side
    // Refinement starts no tile later than this share of the frame's budget from the frame's
    // start, less the time kept for the resolve: what is left is for static work (missing
    // tiles, look-ahead, prefetching). Against 0.8, on the gallery, teapot and courtyard at
    // 640x360 (two runs each, alternating): +1.2-2.0, +1.2-2.9 and +0.4-1.8 dB median,
    // temporal RMSE lower; 0.6 cost 2.4 and 5 dB (docs/playback.md).
    double until = 0.9;
    // QualityRegulatorOptions::refinedShare while refining: a frame's own step is chosen to
    // take about this share of what it would otherwise, leaving the rest to refinement.
    double baseShare = 1.0;
    // QualityRegulatorOptions::slowDownAt while refining. A frame's own step need only fit
    // with refinement's minimum after it (refinement then stops at its deadline): stepping
    // down at 0.7 had moved the teapot and the gallery at 640x360 to per pixel at footprint
    // x2 on frames whose per-pixel pass took 23-24 ms of 33, to refine only back to per
    // pixel. At 0.8, runs alternating with 0.7: frames at 38 dB or more from constant
    // quality, teapot 48, 48, 48 of 48 (0.7: 33, 48, 48), gallery 48, 48, 48, 48, 48, 33
    // (27, 48, 42, 32, 46, 46); deadlines met, gallery 45.7 of 48 on average (46.8), teapot
    // 48 (48); vase and courtyard alike (docs/playback.md).
    double slowDownAt = 0.8;
    double errorWeight = 0.9, ageWeight = 0.1;  // Watson's weights (normalized terms)
    double temporalWeight = 1.0;                // of the temporal error, against the estimated
    double hysteresis = 0.25;
    // At most this many tiles a pass (0: as many as the deadline allows): a fixed amount of
    // refinement, whatever the machine's speed.
    int maxTiles = 0;
};

// A step to refine to: DynamicOptions' shading rate and footprint scale.
struct RefineStep {
    ShadingRate rate = ShadingRate::Sample;
    float footprintScale = 1.0f;
    bool operator==(const RefineStep&) const = default;
};

class TileRefiner {
  public:
    explicit TileRefiner(const RefineOptions& options = {}) : options_(options) {}

    const RefineOptions& options() const { return options_; }

    // After `dynamic` shaded a frame at step `base` and resolved it into `image`: refines
    // tiles to each of `better` in turn (better and better, at most
    // RefineStats::kMaxSteps - 1), none started after `deadline`, and resolves `image`
    // again. The tiles refinement found missing are appended to `missing`.
    void refine(DynamicPhase& dynamic, const RefineStep& base, std::span<const RefineStep> better,
                std::chrono::steady_clock::time_point deadline, Image& image, RefineStats& stats,
                std::vector<TileRequest>& missing);

    // Of the time a refinement has, the share to keep for what follows its passes (the
    // resolve of the pixels near the tiles refined, and the accounting): both grow with the
    // tiles refined, so the share is what they took against the passes the last time
    // anything was refined (0.5 until then).
    double finishShare() const {
        return lastPass_ + lastFinish_ > 0.0 ? lastFinish_ / (lastPass_ + lastFinish_) : 0.5;
    }

  private:
    struct Tile {
        PixelRect rect;
        double contrast = 0.0;  // this frame's, in the cheap image
        double error = 0.0, priority = 0.0;
        float mean[3] = {0, 0, 0};       // the final image's mean RGB, last frame (meansKept_)
        float cheapMean[3] = {0, 0, 0};  // this frame's cheap image's
        int age = 0;                     // frames since last refined to the best step
        bool refinedLast = false;        // refined (to any step) in the last frame
        bool seen = false;               // any surface in it this frame
        int step = 0;                    // where it ended this frame: 0 the base, k better[k - 1]
    };
    void layOut(int width, int height);
    void measure(const DynamicPhase& dynamic, const Image& image);
    std::vector<uint32_t> order();
    // reach: the resolve filter's, in pixels (SampleLayout::filterReach).
    void account(const Image& cheap, const Image& image, int best, int reach, RefineStats& stats);

    RefineOptions options_;
    int width_ = 0, height_ = 0, tileSize_ = 0;
    bool meansKept_ = false;  // the tiles' means are a last frame's (not since layOut)
    std::vector<Tile> tiles_;
    Image cheap_;  // the frame before refinement, in the tiles refined (account() reads no more)
    std::vector<double> gain_;      // per tile: the squared change refinement made
    std::vector<uint8_t> changed_;  // per tile: refined, or next to one refined
    // Measured squared change per unit of contrast from the base to each step (index as
    // Tile::step), < 0 until measured: kept while the base and the steps stay the same.
    std::vector<double> errorPerContrast_;
    RefineStep base_;
    std::vector<RefineStep> better_;
    double lastPass_ = 0.0, lastFinish_ = 0.0;  // the last refinement that refined tiles
    double lastPriorities_ = 0.0;               // the last measure() and order(), seconds
};

}  // namespace mpshade
