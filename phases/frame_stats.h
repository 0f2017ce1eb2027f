// frame_stats.h -- what one frame cost; written to stats.json by the CLI.
#pragma once

#include <cstdint>
#include <vector>

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
    }
    return "unknown";
}

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

    // Multi-phase rendering only (zero for the reference renderer).
    int staticRuns = 0;               // objects (re)processed by the static phase this frame
    double staticSeconds = 0.0;       // of wallSeconds: static phase (dicing, tile fills)
    double fillSeconds = 0.0;         // of staticSeconds: shader-map tile fills
    double warpSeconds = 0.0;         // dynamic TSI: fixed-point warp, culling
    double rasterSeconds = 0.0;       // dynamic TSI: binning and rasterization
    double shadeSeconds = 0.0;        // interpolation, probes, the dynamic shader, compositing
    double resolveSeconds = 0.0;      // the pixel filter
    uint64_t staticInstructions = 0;  // static shader instructions, times lanes
    uint64_t facets = 0;              // facets of the drawn objects' representations
    uint64_t facetsRasterized = 0;    // facet-tile pairs rasterized
    uint64_t fragments = 0;           // facet-sample hits tested against the depth buffer
    uint64_t verticesWarped = 0;
    uint64_t facetBytes = 0;    // memory of the drawn objects' facets and attributes
    uint64_t objectsDrawn = 0;  // objects in view this frame
    // Shader maps: distinct tiles this frame's probes asked for that were not resident,
    // tiles filled (of them, built from their children), texels filled, and what stays
    // resident after the frame (tiles and bytes, all maps).
    uint64_t tilesRequested = 0;
    uint64_t tilesFilled = 0;
    uint64_t tilesFromChildren = 0;
    uint64_t texelsFilled = 0;
    uint64_t residentTiles = 0;
    uint64_t residentBytes = 0;
    uint64_t residentPinnedBytes = 0;  // of residentBytes: the always-resident levels'
    uint64_t tilesEvicted = 0;         // dropped to keep the maps under their memory budget
    uint64_t probes = 0;               // bilinear probes
    uint64_t probeFallbacks = 0;  // answered from a coarser level (zero when render fills first)
    int shadePasses = 0;          // shading passes: 1, plus one per round of fills
    // The frame was rendered single-phase (by the reference renderer): the static work it
    // needed was estimated to cost more than shading the frames it would serve from scratch
    // (multiphase_renderer.h). Every figure above is then the reference's.
    bool singlePhase = false;

    // A frame budget (MultiphaseOptions::frameBudgetSeconds; `mpshade play`): the budget,
    // whether the frame's work fit it, the tiles its probes lacked that were left for later
    // frames, and the objects whose static phase was due but put off (they were drawn from
    // their last representation).
    double budgetSeconds = 0.0;
    bool deadlineMet = true;
    uint64_t tilesDeferred = 0;
    int rebuildsDeferred = 0;
    int builtAhead = 0;  // objects built in this frame's slack for frames ahead that see them
    // Prefetching in the frame's slack (MultiphaseRenderer::prefetch): tiles predicted by a
    // low-resolution look at a frame ahead (claim 11) and next to tiles lacked (claim 10),
    // those filled; and of the tiles prefetched before, those this frame's probes read
    // first (used) and those dropped, or left unread for
    // MultiphaseOptions::prefetchPatienceFrames, unread (wasted).
    uint64_t tilesPredicted = 0, tilesAdjacent = 0, tilesPrefetched = 0;
    bool predictionAbandoned = false;  // the prediction ran past the slack and was dropped
    uint64_t prefetchUsed = 0, prefetchWasted = 0;
    double prefetchSeconds = 0.0;  // of staticSeconds: predicting and prefetching
    // The background filler (MultiphaseOptions::backgroundFills), since the last frame:
    // tiles it filled and dropped, and its worker's wall time (alongside the frames, not
    // within wallSeconds).
    uint64_t backgroundTilesFilled = 0, backgroundTilesEvicted = 0;
    double backgroundSeconds = 0.0;
    // The controller's own work, within wallSeconds: re-run triggers and deferrals, cache
    // bookkeeping (eviction, prefetch accounting), the regulator.
    double controllerSeconds = 0.0;
    std::vector<StaticRunDue> staticRunsDue;  // every object whose static phase was due
};

}  // namespace mpshade
