#include "phases/representation_choice.h"

#include <algorithm>
#include <cstdio>

namespace mpshade {

double shadingPointsPerPixel(ShadingRate rate, int samplesPerPixel) {
    return rate == ShadingRate::Sample ? static_cast<double>(samplesPerPixel)
                                       : (rate == ShadingRate::Pixel ? 1.0 : 0.25);
}

double staticRunNs(const RepresentationCostModel& model, double staticCostUnits) {
    return staticCostUnits * model.nsPerCostUnit + model.geometryPointNs;
}

double referenceNsPerSample(const RepresentationCostModel& model, double originalCostUnits) {
    return originalCostUnits * model.referenceNsPerCostUnit + model.referenceSampleNs;
}

RepresentationChoice chooseRepresentation(const ObjectCostInputs& in,
                                          const RepresentationCostModel& model) {
    const double frames = std::max(1, in.frames);
    const double staticPointNs = staticRunNs(model, in.staticCostUnits);
    const double points =
        in.coveredPixels * shadingPointsPerPixel(in.shadingRate, in.samplesPerPixel);
    // Combined: a vertex per two facets, shaded again at every run.
    const double facetsStatic =
        0.5 * in.combinedFacets * staticPointNs * std::max(1, in.combinedRuns);
    const double facetsFrame = in.combinedFacets * model.facetNs + points * model.vertexPointNs;
    // Separate: the texels frames ask for and the always-resident levels, unless built.
    const double samplesScale = in.shadingRate == ShadingRate::Sample  ? in.samplesPerPixel / 4.0
                                : in.shadingRate == ShadingRate::Pixel ? 1.0
                                                                       : 0.25;
    const double footprint = 0.6 / std::max(0.05f, in.footprintScale);
    const double texelsPerPixel = model.texelsPerCoveredPixel * samplesScale * footprint *
                                  footprint * (in.elongation / model.typicalElongation);
    // The always-resident levels, when filled up front (ShaderMapOptions::fillPinnedUpFront;
    // otherwise only the tiles frames ask for, already counted).
    const double pinnedTexels = in.pinnedUpFront ? in.charts * model.pinnedTexelsPerChart : 0.0;
    const double runs = in.haveMap ? 0.0 : in.coveredPixels * texelsPerPixel + pinnedTexels;
    const double mapStatic = runs * staticPointNs;
    const double mapFrame = points * model.mapPointNs;
    // Direct: the whole shader at every point, nothing stored.
    const double directFrame =
        points * (model.directPointNs + in.originalCostUnits * model.directNsPerCostUnit);

    RepresentationChoice c;
    c.facetsSeconds = (facetsStatic + frames * facetsFrame) * 1e-9;
    c.mapSeconds = (mapStatic + frames * mapFrame) * 1e-9;
    c.facetsStaticSeconds = facetsStatic * 1e-9;
    c.facetsFrameSeconds = facetsFrame * 1e-9;
    c.mapStaticSeconds = mapStatic * 1e-9;
    c.mapFrameSeconds = mapFrame * 1e-9;
    c.directFrameSeconds = directFrame * 1e-9;
    c.singlePhaseFrameSeconds = in.coveredPixels * static_cast<double>(in.samplesPerPixel) *
                                referenceNsPerSample(model, in.originalCostUnits) * 1e-9;
    char text[320];
    std::string tooBig;
    if (in.channels == 0) {
        // Nothing to store (factoring.h, storeAboveCost): the facets need only the
        // geometric tolerance, and no map is made.
        c.kind = Representation::ShaderMap;
        c.mapSeconds = frames * mapFrame * 1e-9;
        c.mapStaticSeconds = 0.0;
        std::snprintf(text, sizeof text,
                      "auto: geometry only; the static part (%.0f cost units a point) costs "
                      "less than reading it back, so the dynamic part runs the whole shader on "
                      "facets diced to the geometric tolerance",
                      in.recomputedCostUnits);
        c.reason = text;
        return c;
    }
    if (!in.haveMap && !shaderMapFits(in, tooBig, model)) {
        c.kind = Representation::Facets;
        c.reason = "auto: facets; " + tooBig;
        return c;
    }
    if (in.pinnedBytes > model.maxPinnedBytes && !in.haveMap) {
        c.kind = Representation::Facets;
        std::snprintf(text, sizeof text,
                      "auto: facets; a shader map's always-resident levels of %d charts would "
                      "take %.0f MB",
                      in.charts, in.pinnedBytes / 1048576.0);
    } else if (in.combinedFacets > model.maxFacetsPerScreenPixel * in.screenPixels) {
        c.kind = Representation::ShaderMap;
        std::snprintf(text, sizeof text,
                      "auto: shadermap; facets would number %.3g, over %.0f per screen pixel",
                      in.combinedFacets, model.maxFacetsPerScreenPixel);
    } else if (!in.haveMap &&
               pinnedTexels > model.maxPinnedTexelsPerPoint * std::max(points, 1.0)) {
        c.kind = Representation::Facets;
        std::snprintf(text, sizeof text,
                      "auto: facets; a shader map would keep %.3g texels always resident for "
                      "%d charts covering about %.3g shading points",
                      in.charts * model.pinnedTexelsPerChart, in.charts, points);
    } else {
        c.kind =
            c.mapSeconds <= c.facetsSeconds ? Representation::ShaderMap : Representation::Facets;
        std::snprintf(text, sizeof text,
                      "auto: %s; estimated over %d frames: shader map %.3f s (%.3f static + "
                      "%.2f ms a frame), facets %.3f s (%.3f static in %d runs + %.2f ms a "
                      "frame, %.3g facets)",
                      c.kind == Representation::ShaderMap ? "shadermap" : "facets",
                      static_cast<int>(frames), c.mapSeconds, mapStatic * 1e-9, mapFrame * 1e-6,
                      c.facetsSeconds, facetsStatic * 1e-9, std::max(1, in.combinedRuns),
                      facetsFrame * 1e-6, in.combinedFacets);
    }
    c.reason = text;
    return c;
}

bool shaderMapFits(const ObjectCostInputs& in, std::string& reason,
                   const RepresentationCostModel& model) {
    if (in.pinnedTiles <= model.maxPinnedTiles) return true;
    char text[200];
    std::snprintf(text, sizeof text,
                  "a shader map of %d charts would keep %.3g tiles always resident (at most "
                  "%.3g)",
                  in.charts, in.pinnedTiles, model.maxPinnedTiles);
    reason = text;
    return false;
}

}  // namespace mpshade
