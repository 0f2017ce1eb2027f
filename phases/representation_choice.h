// representation_choice.h -- "representation": "auto": which intermediate representation
// costs an object less over the frames it is seen in ("model only what the scene needs").
//
// Facets carrying the n-tuple per vertex (combined) need no probes, but are sub-pixel:
// about 16 facets per square pixel of surface to warp and rasterize every frame, and the
// static part runs once per vertex. A shader map (separate) rides on facets only as fine as
// the geometric error allows (a handful per object), costs a probe per shading point, and
// the static part runs once per texel the frames ask for (about 3 per covered pixel:
// two pyramid levels, tile and border waste), plus once per texel of the coarsest six
// levels of every chart, which are always resident. So maps win for objects seen in many
// frames or large on screen; facets win for objects of many tiny charts (point clouds),
// whose always-resident levels alone would outweigh them, and for expensive static parts
// seen in few frames.
//
// The estimate is coarse on purpose -- it must be cheap, and made before either exists --
// and its constants (nanoseconds per unit of work, on the machines the figures in
// docs/multiphase.md were measured on) are documented here and tested as a rule, not a
// number: the choice and its reason go to stats.json.
#pragma once

#include <string>

#include "scene/scene.h"

namespace mpshade {

struct RepresentationCostModel {
    double facetNs = 30.0;            // warp, bin and rasterize one facet, per frame
    double vertexPointNs = 60.0;      // interpolate and shade one point of a facets object
    double mapPointNs = 140.0;        // interpolate, probe and shade one point of a map object
    double nsPerCostUnit = 1.4;       // the static shader, per point and opCost unit
    double facetsPerSquarePixel = 16.0;  // combined: facets per square pixel of surface
    double texelsPerPixel = 3.0;      // separate: texels filled per covered pixel
    double pinnedTexelsPerChart = 34.0 * 34.0;  // the 32 x 32 level with its border
    double mapBytesPerChartLimit = 64.0 * 1024 * 1024;  // pinned levels beyond this: facets
};

// What the estimate needs to know of an object at its first static run.
struct ObjectCostInputs {
    double surfacePixels = 0.0;  // its surface area in square pixels at this view
    double coveredPixels = 0.0;  // the screen area it covers, estimated
    bool closed = false;         // back faces culled at dicing
    int charts = 1;
    int frames = 1;                // frames it is seen in
    double staticCostUnits = 0.0;  // the static part's opCost per point
    int supersamples = 4;          // program runs per directly evaluated texel (k^2)
    int samplesPerPixel = 4;
    ShadingRate shadingRate = ShadingRate::Pixel;
    double pinnedBytes = 0.0;  // memory of the map's always-resident levels
};

struct RepresentationChoice {
    Representation kind = Representation::ShaderMap;
    std::string reason;
    double facetsSeconds = 0.0, mapSeconds = 0.0;  // estimated over the frames seen
};

RepresentationChoice chooseRepresentation(const ObjectCostInputs& in,
                                          const RepresentationCostModel& model = {});

}  // namespace mpshade
