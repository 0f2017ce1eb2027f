// multiphase_options.h -- how a MultiphaseRenderer (multiphase_renderer.h) renders: its
// static and dynamic phases' options, the tile cache's budget, when a frame may be
// rendered single-phase, and the frame budget of a locked frame rate with what its slack
// is spent on. Plain data with documented defaults.
#pragma once

#include <cstddef>
#include <optional>

#include "controller/footprint_calibration.h"
#include "controller/tile_refiner.h"
#include "phases/dynamic_phase.h"
#include "phases/phase_trace.h"
#include "phases/representation_choice.h"
#include "phases/static_phase.h"

namespace mpshade {

// Constant quality fills every tile a frame's probes find missing before it shades, so no probe
// falls back and the maps' always-resident levels are filled only where frames ask for
// them (on the courtyard's 24 frames, filling them all up front took 1.0 s of 6.3).
inline StaticPhaseOptions constantQualityStaticPhase() {
    StaticPhaseOptions o;
    o.shaderMap.fillPinnedUpFront = false;
    return o;
}

struct MultiphaseOptions {
    StaticPhaseOptions staticPhase = constantQualityStaticPhase();
    DynamicOptions dynamic;  // its shadingRate is the scene's unless shadingRate is set
    // Each object's footprint chosen from measured error at the first constant-quality frame
    // that shows it well (footprint_calibration.h); its objectFootprint is then set per frame
    // from those choices. Off: every object's is 1 (or dynamic.objectFootprint as given).
    FootprintCalibrationOptions footprints;
    std::optional<ShadingRate> shadingRate;
    RepresentationCostModel costModel;
    // The shader maps' tiles stay under this many bytes: before tiles are filled, the tiles
    // unused longest are dropped (never the always-resident levels, nor a tile the frame
    // being rendered has used).
    size_t mapMemoryBytes = size_t{96} << 20;
    // Forces every object's representation (tests, benchmarks); unset: the scene's.
    std::optional<Representation> representation;
    // Never slower than single-phase, per object: an object the scene leaves to auto whose
    // stored representation measures costlier a frame than the reference, two frames
    // running, goes direct (static_run_triggers.h, compareWithReference).
    bool directWhenSlower = true;
    // A frame whose due static work, with the dynamic frames it would serve, is estimated
    // to cost more than rendering those frames single-phase is rendered by the reference
    // renderer instead, and nothing is built (a camera cut every frame, a short request).
    // Off: every frame is multi-phase.
    bool singlePhaseFrames = true;
    // An object's static phase is built for whichever of the present view and this many
    // frames' views ahead has the range holding the longest run of frames from the present
    // one (view_lookahead.h): a camera moving steadily leaves the range less often. Every
    // path that builds (in the frame, in the background, ahead of a locked frame rate's
    // frames) builds for the same view; 0: the present view, always.
    int viewLookahead = 24;
    // Where every phase reports its spans (phase_trace.h; not owned, must outlive the
    // renderer). Null: nowhere, and nothing is measured for it.
    PhaseTrace* trace = nullptr;
    // Above 0: the frame rate is locked (`mpshade play`). A frame shades once, probes
    // missing tiles falling back to the finest coarser level resident; then, in the time left
    // of this many seconds, the tiles they found missing are filled (coarser levels first: each
    // serves more of the screen, for less) and the rest left for later frames. An object
    // whose static phase is due is drawn from its last representation unless its expected
    // run (ObjectSlot::rebuildSeconds) fits the time left; one never built is always built.
    // 0: constant quality.
    double frameBudgetSeconds = 0.0;
    // With a frame budget, the share of it static work gets even when the dynamic phase
    // took the whole budget: frames late anyway still make progress towards full quality.
    double minimumStaticShare = 0.1;
    // With a frame budget: the frame, once resolved, refined by image tile at finer rates in
    // order of priority (tile_refiner.h). Off by default; playback turns it on.
    RefineOptions refine;
    // The photometric re-run trigger (static_inputs.h): an object whose static part reads
    // animated inputs (through bake()) runs its static phase again once one of them moved
    // by more than this share of its span over the scene since the last run.
    float staticInputTolerance = 0.02f;
    // A prefetched tile no frame read within this many frames counts as wasted (it stays
    // resident, an ordinary tile for the cache).
    int prefetchPatienceFrames = 30;
    // With a frame budget: the missing tiles a frame had no time left to fill are queued
    // for a worker thread that fills them at idle priority (background_filler.h), from the
    // end of the frame's fills until the next frame starts -- and, with
    // backgroundDuringFrames, alongside its dynamic phase too. At most backgroundQueue are
    // queued (the newest frame's, coarser levels first). Off: they wait for a later
    // frame's slack.
    bool backgroundFills = false;
    size_t backgroundQueue = 4096;
    bool backgroundDuringFrames = false;
    // With a frame budget: an object whose static phase is due again for a new view (its
    // range left, its facets grown too long) and whose rebuild makes no shader map is
    // rebuilt on a worker thread at idle priority while the frames draw its last
    // representation, and swapped in at the start of a frame after (background_builder.h).
    // Off: such rebuilds run in a frame only when their expected cost fits its time left.
    bool backgroundRebuilds = false;
    // The workers at idle priority; false: normal priority (a caller that waits on it while
    // other processes load the machine, as tests do).
    bool backgroundIdlePriority = true;
};

}  // namespace mpshade
