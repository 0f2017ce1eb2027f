// object_slot.h -- everything the controller keeps for one scene object across frames: its
// current representation, what its last static run saw (for the re-run triggers,
// controller/static_run_triggers.h), what the last frame cost it, and its report for
// stats.json. One slot per object, indexed like Scene::objects.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "controller/footprint_calibration.h"
#include "phases/dynamic_phase.h"
#include "phases/object_representation.h"
#include "phases/static_inputs.h"
#include "phases/static_phase.h"

namespace mpshade {

// Per object, for stats.json: what the static phase chose and did.
struct ObjectReport {
    std::string name;
    Representation kind = Representation::Auto;  // Auto: not built yet (never seen)
    std::string reason;
    int staticRuns = 0;
    int framesDrawn = 0;
    uint64_t facets = 0;  // of its current representation
    uint64_t facetBytes = 0;
    uint64_t residentTiles = 0, mapBytes = 0;
    float longestEdgePixels = 0.0f;  // combined: last frame's longest projected facet edge
    StaticCosts staticCosts;
    // Its footprint calibration (footprint_calibration.h): what was measured (no pixels: not
    // measured) and the scale chosen.
    FootprintMeasure footprint;
    float footprintScale = 1.0f;
};

struct ObjectSlot {
    // Owned; null until a frame sees the object (or after MultiphaseRenderer::
    // discardStaticWork). Replaced whole by each static run; the dynamic phase reads it.
    std::unique_ptr<ObjectRepresentation> representation;
    Representation kind = Representation::Auto;  // chosen at its last static run
    // Combined representation: the longest projected facet edge the last frame measured,
    // pixels (the sampling fiducial; 0 right after a static run).
    float longestEdge = 0.0f;
    // What its next static run should cost, wall seconds: its last run's, less the making of
    // a shader map the next run keeps (StaticCosts::keptMapSeconds: a rebuild re-dices; the
    // map's tiles stay valid).
    double rebuildSeconds = 0.0;
    // Its footprint multiplier (DynamicOptions::objectFootprint), once measured: chosen by
    // MultiphaseRenderer::calibrateFootprints, kept for the rest of the render.
    bool footprintMeasured = false;
    float footprintScale = 1.0f;
    // Its shading points at the last frame whose pixels were too few to measure it (0:
    // none): it is looked at again once it shades twice as many.
    uint64_t footprintTooFewAt = 0;
    // The animated inputs its static part reads, how far each moves over the scene (its
    // span), and their values at its last static run (the photometric fiducial).
    StaticInputs staticInputs;
    std::vector<float> inputSpans, builtInputs;
    // The last frame: its static work (building, filling its tiles), seconds summed over
    // threads; its dynamic work (all zero when not drawn or rendered single-phase).
    double frameStaticSeconds = 0.0;
    ObjectFrameCost frameDynamic;
    bool builtThisFrame = false;
    uint64_t frameTilesFilled = 0;  // the last frame's, for its map
    // Never slower than single-phase (static_run_triggers.h): the frames running its stored
    // representation cost more than the reference would have; once enough, it goes direct.
    int framesSlowerThanReference = 0;
    bool goesDirect = false;
    float measuredMs = 0.0f, referenceMs = 0.0f;  // the last frame's, estimated CPU ms
    ObjectReport report;
};

}  // namespace mpshade
