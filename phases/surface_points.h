// surface_points.h -- the dynamic phase's shading of visible surface points: for each point
// (a facet and a screen position), where the camera ray through that position meets the
// facet, the attributes there, the n-tuple (interpolated from the facet's vertices, or
// probed from the shader map with the point's footprint), and the dynamic shader S_d.
//
// Barycentric weights come from intersecting the ray with the facet in object space
// (Moller and Trumbore 1997) rather than from the rasterizer: they are perspective
// correct by construction, exact for facets clipped at the near plane (whose corners
// may be behind the eye), and need not be carried for every sample a facet is tested
// against. With the ray direction linear in the screen position, d = d0 + x dx + y dy,
// each weight is a ratio of two linear functions of (x, y), so its screen derivatives --
// and the chart coordinates' footprint for the probe -- are exact for the facet's plane.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "phases/object_representation.h"
#include "shadermaps/probe.h"
#include "shading/shading_batch.h"

namespace mpshade {

// One object as this frame sees it. Object space throughout.
struct ObjectView {
    const ObjectRepresentation* rep = nullptr;
    const ShadingUniforms* uniforms = nullptr;
    glm::vec3 eye{0.0f};
    // The (unnormalized) direction of the ray through screen position (x, y) pixels.
    glm::vec3 d0{0.0f}, dx{0.0f}, dy{0.0f};
    float footprintScale = 1.0f;  // multiplies the probe footprint of one pixel
};

// Points to shade: facet and screen position (pixels), n of each.
struct SurfacePoints {
    const uint32_t* facet = nullptr;
    const float* x = nullptr;
    const float* y = nullptr;
    size_t n = 0;
};

struct SurfaceShadingScratch {
    ShadingBatch batch;
    std::vector<ProbeQuery> queries;
    std::vector<float> workspace;
    std::vector<float> b1, b2;       // per point: barycentric weights
    std::vector<float> derivatives;  // their screen derivatives: 4 rows of n points
    std::vector<uint32_t> runs;     // the first point of each run on one facet, then n (grown only)
    std::vector<float> facetRays;   // per run, its facet's constants for the ray hits
    std::vector<TileKey> reported;  // the probes' report buffer
    std::vector<TileKey> missing;   // missing tiles of the calls since it was cleared
};

struct SurfaceShadingCounters {
    uint64_t instructions = 0;
    uint64_t nonFinite = 0;  // results that were NaN or infinite (made opaque black)
    uint64_t probes = 0;     // bilinear probes of shader maps
    uint64_t fallbacks = 0;  // of them, answered from a coarser level
    uint64_t missingProbes = 0;
    // CPU seconds: steps 1-4 (positions to chart footprints), step 5 (probes), step 6 (the
    // dynamic shader and its results made finite).
    double interpolateSeconds = 0.0, probeSeconds = 0.0, kernelSeconds = 0.0;
};

// Shades points.n points of `view`'s object into color and opacity (3 floats per point
// each, sanitized: compositing.h). Tiles the probes found missing are added to scratch.missing.
// With stopAtMissing, a point whose probes found a tile missing gets missed[i] = 1 and a
// meaningless result (it is to be shaded again once the tiles are filled); otherwise
// missing tiles fall back to coarser levels. Returns how many points missed.
size_t shadeSurfacePoints(const ObjectView& view, const ProbeOptions& probe, bool stopAtMissing,
                          const SurfacePoints& points, float* color, float* opacity,
                          uint8_t* missed, SurfaceShadingScratch& scratch,
                          SurfaceShadingCounters& counters);

// Step 6 of shadeSurfacePoints alone: the dynamic shader on n points whose inputs `in`
// points at (shadingInputRows and shadingChannels of scratch.batch as shadeSurfacePoints
// leaves them, or the values a caller kept), its results -- written to scratch.batch's
// outputs, which must have room for n -- made finite into color and opacity (3 floats per
// point each).
void runDynamicShader(const ObjectView& view, const ShadingInputs& in, size_t n, float* color,
                      float* opacity, SurfaceShadingScratch& scratch,
                      SurfaceShadingCounters& counters);
// The ShadingBatch input rows shadeSurfacePoints fills for rep's points that rep's dynamic
// shader may read (P, I and its geometry rows), ascending; the n-tuple's channels (batch
// channels 0 .. shadingChannels - 1) come besides.
std::vector<int> shadingInputRows(const ObjectRepresentation& rep);
size_t shadingChannels(const ObjectRepresentation& rep);

}  // namespace mpshade
