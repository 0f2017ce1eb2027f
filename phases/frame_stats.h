// frame_stats.h -- what one frame cost; written to stats.json by the CLI.
#pragma once

#include <cstdint>
#include <vector>

#include "phases/dynamic_phase.h"
#include "phases/static_phase.h"

namespace mpshade {

// Why an object's static phase was due this frame, with the fiducial that said so (Lengyel
// and Snyder 1997, sec. 4): geometric (the view moved out of the range: degrees the view
// direction turned or the eye moved around the object, or the ratio of view distances),
// sampling (facets carrying the n-tuple measured longer than P/2 last frame, pixels; the
// image height changed). `measured` beyond `threshold` is the trigger.
struct StaticRunDue {
    enum Cause {
        FirstSeen,
        ViewDirection,
        Distance,
        AngleAround,
        FacetsTooLong,
        ImageSize,
        StaticInput,  // measured: the largest move of an input over its span (static_inputs.h)
        // Its stored representation cost more a frame than the reference would spend on it,
        // frames running (static_run_triggers.h): measured and threshold in ms of CPU time.
        SlowerThanReference,
    };
    uint32_t object = 0;
    Cause cause = FirstSeen;
    float measured = 0.0f, threshold = 0.0f;
    bool deferred = false;  // a frame budget put it off: drawn from its last representation
};
inline const char* staticRunCauseName(StaticRunDue::Cause cause) {
    switch (cause) {
        case StaticRunDue::FirstSeen:
            return "first seen";
        case StaticRunDue::ViewDirection:
            return "view direction left the range";
        case StaticRunDue::Distance:
            return "view distance left the range";
        case StaticRunDue::AngleAround:
            return "view moved around the object beyond the range";
        case StaticRunDue::FacetsTooLong:
            return "facets longer than P/2";
        case StaticRunDue::ImageSize:
            return "image height changed";
        case StaticRunDue::StaticInput:
            return "an animated input of its static part moved";
        case StaticRunDue::SlowerThanReference:
            return "its stored representation cost more than the reference would: direct";
    }
    return "unknown";
}

// Static work within a frame: the builds of objects whose static phase was due and the
// shader-map tiles filled, as the static phase counted them (`work`: runs, instructions,
// tiles and texels; `work.seconds` sums the tasks' own times), with the frame's wall time
// spent on it.
struct StaticFrameStats {
    StaticCosts work;
    double seconds = 0.0;           // of FrameStats::wallSeconds
    double fillSeconds = 0.0;       // of seconds: shader-map tile fills
    std::vector<StaticRunDue> due;  // every object whose static phase was due

    StaticFrameStats& operator+=(const StaticFrameStats& o) {
        work += o.work;
        seconds += o.seconds;
        fillSeconds += o.fillSeconds;
        due.insert(due.end(), o.due.begin(), o.due.end());
        return *this;
    }
};

// The shader maps' tiles: the missing tiles (the distinct tiles this frame's probes asked
// for that were not resident, over every shading pass; stats.json's tiles_requested), those
// dropped to keep the maps under their memory budget, and what stays resident after the
// frame (tiles and bytes, all maps; a snapshot, so a sum of frames keeps the last).
struct TileStats {
    uint64_t missing = 0;
    uint64_t evicted = 0;
    uint64_t resident = 0;
    uint64_t residentBytes = 0;
    uint64_t residentPinnedBytes = 0;  // of residentBytes: the always-resident levels'

    TileStats& operator+=(const TileStats& o) {
        missing += o.missing;
        evicted += o.evicted;
        resident = o.resident;
        residentBytes = o.residentBytes;
        residentPinnedBytes = o.residentPinnedBytes;
        return *this;
    }
};

// A frame budget (MultiphaseOptions::frameBudgetSeconds; `mpshade play`): the budget,
// whether the frame's work fit it, the tiles its probes found missing that were left for later
// frames, and the objects whose static phase was due but put off (they were drawn from
// their last representation).
struct BudgetStats {
    double seconds = 0.0;
    bool deadlineMet = true;
    uint64_t tilesDeferred = 0;
    int rebuildsDeferred = 0;
    // Of rebuildsDeferred: queued for the background builder or under way there
    // (MultiphaseOptions::backgroundRebuilds).
    int rebuildsInBackground = 0;
    // Fill chunks stopped at the end of the frame's fill time (controller/tile_filler.h):
    // their tiles under way dropped and left for later.
    int fillsStopped = 0;
    int builtAhead = 0;  // objects built in this frame's slack for frames ahead that see them
};

// Refinement by image tile in a played frame (controller/tile_refiner.h): the frame shaded
// at its step, then tiles in order of priority shaded again at better steps until the
// refinement's deadline.
struct RefineStats {
    static constexpr int kMaxSteps = 8;
    bool ran = false;  // refinement was on and had a better step to go to
    int tileSize = 0;  // pixels a side
    int tiles = 0;     // image tiles that see any surface
    int steps = 0;     // the frame's step and those better it could go to
    // Per step (0: the frame's own, k: the k-th better one), the pixels of the image there
    // once refined, and the tiles refined to it (a tile counts at its last).
    uint64_t pixelsAt[kMaxSteps] = {};
    int refined[kMaxSteps] = {};
    // Per step, its shading rate and footprint scale (at the frame's samples per pixel).
    ShadingRate rateAt[kMaxSteps] = {};
    float footprintAt[kMaxSteps] = {};
    // The priority (errorWeight and ageWeight normalized over the image, hysteresis
    // included) of the last tile refined: tiles below it stayed at the cheap step. 0: none
    // refined, or every tile.
    double threshold = 0.0;
    // The mean squared difference over RGB (clamped to [0, 1], as compareImages) that
    // refinement made in the tiles it refined; and the frame's estimated PSNR against
    // constant quality, from the tiles left cheaper times the measured error per unit of
    // their contrast (tile_refiner.h). 99: nothing left; -1: nothing measured yet.
    double gainMse = 0.0;
    double estimatedPsnr = 99.0;
    uint64_t shadingPoints = 0;  // shaded again
    double seconds = 0.0;        // wall: priorities, the passes and the resolve again
    double passSeconds = 0.0;    // of seconds: the passes (shading and compositing tiles)
    double resolveSeconds = 0.0;
};

// Prefetching in the frame's slack (playback.h): tiles predicted by a low-resolution look
// at a frame ahead (claim 11) and next to missing tiles (claim 10), those filled; and of the
// tiles prefetched before, those this frame's probes read first (used) and those dropped,
// or left unread for MultiphaseOptions::prefetchPatienceFrames, unread (wasted).
struct PrefetchStats {
    uint64_t predicted = 0, adjacent = 0, filled = 0;
    bool abandoned = false;  // the prediction ran past the slack and was dropped
    uint64_t used = 0, wasted = 0;
    double seconds = 0.0;  // of StaticFrameStats::seconds: predicting and prefetching

    PrefetchStats& operator+=(const PrefetchStats& o) {
        predicted += o.predicted;
        adjacent += o.adjacent;
        filled += o.filled;
        abandoned = abandoned || o.abandoned;
        used += o.used;
        wasted += o.wasted;
        seconds += o.seconds;
        return *this;
    }
};

// The background filler (MultiphaseOptions::backgroundFills), since the last frame: tiles
// it filled and dropped, and its worker's wall time (alongside the frames, not within
// wallSeconds).
struct BackgroundStats {
    uint64_t tilesFilled = 0, tilesEvicted = 0;
    double seconds = 0.0;
    // The background builder's (MultiphaseOptions::backgroundRebuilds): representations it
    // rebuilt that this frame took up, and their CPU time on its worker.
    int rebuilds = 0;
    double rebuildSeconds = 0.0;

    BackgroundStats& operator+=(const BackgroundStats& o) {
        tilesFilled += o.tilesFilled;
        tilesEvicted += o.tilesEvicted;
        seconds += o.seconds;
        rebuilds += o.rebuilds;
        rebuildSeconds += o.rebuildSeconds;
        return *this;
    }
};

// What one frame cost. The first group is every renderer's; the nested groups are the
// multi-phase renderer's (zero for the reference renderer), each counted where its work is
// done and copied here whole.
struct FrameStats {
    int index = 0;
    float time = 0.0f;         // scene time, seconds
    double wallSeconds = 0.0;  // whole frame, wall clock
    uint64_t samples = 0;      // sub-pixel samples
    uint64_t rays = 0;  // camera rays traced, continuation rays through translucency included
    uint64_t occlusionRays = 0;
    uint64_t shadedPoints = 0;        // shader invocations
    uint64_t shaderInstructions = 0;  // interpreter instructions executed, times lanes
    uint64_t nonFiniteSamples = 0;    // shader results that were NaN/Inf and were zeroed
    // The frame was rendered single-phase (by the reference renderer): the static work it
    // needed was estimated to cost more than shading the frames it would serve from scratch
    // (multiphase_renderer.h). Every figure above is then the reference's.
    bool singlePhase = false;
    uint64_t objectsDrawn = 0;  // objects in view this frame

    StaticFrameStats staticWork;
    DynamicFrameStats dynamic;  // warp, rasterization, shading passes, probes, the resolve
    TileStats tiles;
    BudgetStats budget;
    PrefetchStats prefetch;
    BackgroundStats background;
    RefineStats refine;
    // Objects whose footprints were measured this frame (controller/footprint_calibration.h),
    // and the wall seconds it took (within wallSeconds; its fills are in staticWork too).
    struct FootprintCalibration {
        uint64_t objects = 0;
        double seconds = 0.0;
    } footprintCalibration;
    // The controller's own work, within wallSeconds: re-run triggers and deferrals, cache
    // bookkeeping (eviction, prefetch accounting), the regulator.
    double controllerSeconds = 0.0;
};

}  // namespace mpshade
