// representation_choice.h -- "representation": "auto": which intermediate representation
// costs an object less over the frames it is seen in ("model only what the scene needs").
//
// Facets carrying the n-tuple per vertex (combined) need no probes, but are sub-pixel: the
// dicing survey says how many (often 20-50 per square pixel of surface, both sides of open
// surfaces included), each warped and rasterized every frame, and the static part runs once
// per vertex -- again whenever the view comes closer. A shader map (separate) rides on
// facets only as fine as the geometric error allows (a handful per object), costs a probe
// per shading point, and the static part runs once per texel the frames ask for (several
// per covered pixel: the texels are as small as the sample footprint), plus once per texel
// of the coarsest six levels of every chart, which are always resident. So maps win for
// objects large on screen or seen in many frames; facets win for objects seen in few
// frames with expensive static parts, and for objects of many tiny charts (point clouds),
// whose always-resident levels alone would outweigh them.
//
// The estimate is coarse on purpose -- it must be cheap, and made before either exists --
// and its constants are CPU nanoseconds per unit of work measured on the examples (2-core
// x86-64, docs/multiphase.md). It is made again at each static run, with the view and the
// frames left; a map already built is kept (its tiles are paid for). The choice and its
// reason go to stats.json.
#pragma once

#include <string>

#include "scene/scene.h"

namespace mpshade {

struct RepresentationCostModel {
    // Measured with `mpshade profile SCENE --threads 1` (per object: shading ms a frame over
    // its shading points; the rasterize stage over the facets) on the four examples, each
    // rendered once as the planner chose and once with its curved objects forced to facets
    // (docs/multiphase.md, "The cost model's prices"). Points of a map cost 48-55 ns on the
    // floors and 85-140 on small curved objects; points of facets 94-150 on the same
    // objects: no cheaper, so facets only pay where their static work is much less. (Both
    // had been priced for a slower dynamic phase: 290 and 170.)
    double facetNs = 25.0;         // warp, bin and rasterize one facet of the combined, per frame
    double vertexPointNs = 110.0;  // interpolate and shade one point of a facets object
    double mapPointNs = 100.0;     // interpolate, probe and shade one point of a map object
    // The static shader, per point and opCost unit, and evaluating the surface and setting
    // up one point before any shader work (measured on the always-resident levels of a
    // 300,000-disc point cloud: 68 ns a texel). These price a whole static run by its
    // points alone: a texel alone costs less (the TileFill benchmarks, a vase chart's texels
    // on one thread: 136 ns for a static part of 0 units, 1510 for marble's 3497, about 0.4
    // ns a unit), but a run also dices and builds its occlusion rays' scene, and a map fills
    // 3-5 times the texels texelsPerCoveredPixel counts (docs/multiphase.md). Priced at 0.4
    // and 130, a camera cut every frame went multi-phase and cost 4.6 times the reference
    // (`mpshade eval --quick`, the courtyard: 18.4 s against 4.0; at these prices -6%).
    double nsPerCostUnit = 1.4;
    double geometryPointNs = 60.0;
    // The reference renderer, for frames rendered single-phase: per sample, the camera
    // ray, the surface point, compositing and the filter, plus the whole shader per cost
    // unit (its batched shading runs a unit faster than the fills above). Measured in CPU
    // time (wall times 2 cores): the teapot's 614,400 samples of 84 units take 0.27 s, 440
    // ns a sample; the vase's 518,400, a quarter of them marble (3,542 units), 0.32 s.
    double referenceSampleNs = 350.0;
    double referenceNsPerCostUnit = 0.3;
    // Direct: interpolating a point's geometry on facets at the geometric tolerance, then
    // the whole shader batched. Measured on the grazing floor (examples/hard): 115,700
    // points of a 186-unit shader in 10 ms of CPU time, 87 ns a point.
    double directPointNs = 40.0;
    double directNsPerCostUnit = 0.25;
    // Separate: texels filled per covered pixel at 4 samples per pixel, footprint scale 0.6
    // and the elongation of a typical object (below); the texel density goes as the
    // footprint's inverse square, so with the samples (per sample rate) and with 1 / scale^2,
    // and with ObjectCostInputs::elongation.
    double texelsPerCoveredPixel = 12.0;
    // The examples' objects: 1.7-2.2 on curved ones, 2.6-3.4 on their floors; the grazing
    // floor (examples/hard) 12.
    double typicalElongation = 2.5;
    double pinnedTexelsPerChart = 34.0 * 34.0;   // the 32 x 32 level with its border
    double maxFacetsPerScreenPixel = 4.0;        // combined facets beyond this: always a map
    double maxPinnedBytes = 64.0 * 1024 * 1024;  // pinned levels beyond this: facets
    // Pinned texels beyond this many per shading point the object covers: facets (a point
    // cloud's thousand one-pixel discs would each pin a 34 x 34 level).
    double maxPinnedTexelsPerPoint = 32.0;
    // Always-resident tiles beyond this: facets, whatever the scene asks (a shared tile pool
    // holds 2^22 tiles; nine a chart).
    double maxPinnedTiles = double(1 << 20);
};

// What the estimate needs to know of an object at a static run.
struct ObjectCostInputs {
    double combinedFacets = 0.0;  // from the dicing survey at this view
    double coveredPixels = 0.0;   // the screen area it covers, estimated
    int charts = 1;
    int frames = 1;        // frames it is seen in, from now on
    int combinedRuns = 1;  // static runs the combined would need over those frames
    double screenPixels = 1.0;
    double staticCostUnits = 0.0;    // the static part's opCost per point
    double originalCostUnits = 0.0;  // the whole shader's, as the reference runs it
    int samplesPerPixel = 4;
    ShadingRate shadingRate = ShadingRate::Sample;
    float footprintScale = 1.0f;  // the dynamic phase's probe footprint scale
    // How many times a facing surface's texels a map fills per covered pixel, on the mean
    // over the pixels: the footprint's major over minor axis, capped at the probe's
    // levelAnisotropy (footprintElongation, representation_planner.h). A sphere about 2, a
    // floor near the horizon the cap; unmeasured, a typical object's.
    double elongation = 2.5;
    int channels = 1;                  // floats of the n-tuple; 0: nothing static is stored
    double recomputedCostUnits = 0.0;  // with 0 channels: the static work the dynamic part repeats
    bool pinnedUpFront = true;         // a map's always-resident levels are filled when it is made
    double pinnedBytes = 0.0;          // memory of a map's always-resident levels
    double pinnedTiles = 0.0;          // tiles of those levels
    bool haveMap = false;              // a map of it exists already: its cost is paid
};

struct RepresentationChoice {
    Representation kind = Representation::ShaderMap;
    std::string reason;
    double facetsSeconds = 0.0, mapSeconds = 0.0;  // estimated over the frames seen
    // Of those: the static work due now, and each frame's dynamic work, per kind.
    double facetsStaticSeconds = 0.0, facetsFrameSeconds = 0.0;
    double mapStaticSeconds = 0.0, mapFrameSeconds = 0.0;
    double directFrameSeconds = 0.0;  // (a direct representation's static work is dicing)
    // The reference renderer's estimate for one frame of the object.
    double singlePhaseFrameSeconds = 0.0;
};

RepresentationChoice chooseRepresentation(const ObjectCostInputs& in,
                                          const RepresentationCostModel& model = {});

// The model's unit prices, which the estimate above and the controller's pricing of a
// frame's measured work (static_run_triggers.h) share: the shading points a pixel holds at
// `rate`; one run of a static part of `staticCostUnits` (a vertex or a map texel, its
// surface point included), ns; one sample of the reference renderer for a shader of
// `originalCostUnits`, ns.
double shadingPointsPerPixel(ShadingRate rate, int samplesPerPixel);
double staticRunNs(const RepresentationCostModel& model, double staticCostUnits);
double referenceNsPerSample(const RepresentationCostModel& model, double originalCostUnits);

// Whether a shader map of the object fits at all (its always-resident tiles); if not, the
// reason, and the object is rendered with facets even where the scene asks for a map.
bool shaderMapFits(const ObjectCostInputs& in, std::string& reason,
                   const RepresentationCostModel& model = {});

}  // namespace mpshade
