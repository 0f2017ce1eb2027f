#include "phases/representation_choice.h"

#include <algorithm>
#include <cstdio>

namespace mpshade {

RepresentationChoice chooseRepresentation(const ObjectCostInputs& in,
                                          const RepresentationCostModel& model) {
    const double frames = std::max(1, in.frames);
    const double staticPointNs = in.staticCostUnits * model.nsPerCostUnit;
    const double points = in.coveredPixels * (in.shadingRate == ShadingRate::Pixel
                                                  ? 1.0
                                                  : static_cast<double>(in.samplesPerPixel));
    // Combined: sub-pixel facets over the surface (its front only, for closed surfaces),
    // a vertex per two facets.
    const double facets =
        model.facetsPerSquarePixel * in.surfacePixels * (in.closed ? 0.5 : 1.0);
    const double facetsStatic = 0.5 * facets * staticPointNs;
    const double facetsFrame = facets * model.facetNs + points * model.vertexPointNs;
    // Separate: the texels frames ask for and the always-resident levels, each evaluated
    // with supersamples; a few facets per chart.
    const double runs = (in.coveredPixels * model.texelsPerPixel +
                         in.charts * model.pinnedTexelsPerChart) *
                        std::max(1, in.supersamples);
    const double mapStatic = runs * staticPointNs;
    const double mapFrame = 8.0 * in.charts * model.facetNs + points * model.mapPointNs;

    RepresentationChoice c;
    c.facetsSeconds = (facetsStatic + frames * facetsFrame) * 1e-9;
    c.mapSeconds = (mapStatic + frames * mapFrame) * 1e-9;
    char text[256];
    if (in.pinnedBytes > model.mapBytesPerChartLimit) {
        c.kind = Representation::Facets;
        std::snprintf(text, sizeof text,
                      "auto: facets; a shader map's always-resident levels of %d charts would "
                      "take %.0f MB",
                      in.charts, in.pinnedBytes / 1048576.0);
    } else {
        c.kind = c.mapSeconds <= c.facetsSeconds ? Representation::ShaderMap
                                                 : Representation::Facets;
        std::snprintf(text, sizeof text,
                      "auto: %s; estimated over %d frames: shader map %.3f s (%.3f static + "
                      "%.2f ms a frame), facets %.3f s (%.3f static + %.2f ms a frame)",
                      c.kind == Representation::ShaderMap ? "shadermap" : "facets",
                      static_cast<int>(frames), c.mapSeconds, mapStatic * 1e-9, mapFrame * 1e-6,
                      c.facetsSeconds, facetsStatic * 1e-9, facetsFrame * 1e-6);
    }
    c.reason = text;
    return c;
}

}  // namespace mpshade
