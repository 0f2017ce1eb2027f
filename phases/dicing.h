// dicing.h -- the static TSI (patent FIG. 4, claim 24): dice a surface into facets, as
// fine as what they carry needs ("model only what the scene needs"):
//   * EdgeLength (the combined representation, facets carrying the n-tuple per vertex):
//     projected edges at most P/2 (P = pixel spacing) at the representative view, and
//     near P/4 where that allows, as REYES dices grids. The dynamic phase measures the
//     projected edges every frame and the object is diced again when they outgrow P/2.
//   * Flatness (the separate representation, a shader map carrying the shading): every
//     facet within 1/4 pixel of the exact surface -- its deviation, and so its silhouette
//     error -- for every viewpoint in the range. The deviation of a chord is measured at
//     its midpoint against the surface point at the midpoint's chart coordinates, which
//     also bounds how far the interpolated chart coordinates stray (texture swim); a
//     chord's deviation falls with the square of its subdivision, so the rate is
//     8 sqrt(deviation / tolerance) for a line of 8 survey chords. A flat chart with a
//     linear parameterization is two triangles.
//
// Per chart, the edge rates come from each chart edge and row sampled on a 9x9 grid (with
// the chord midpoints between), each chord measured in pixels at the closest the eye
// comes to it (the representative eye, or every eye of the range), stretched by the worst
// off-axis magnification 1 + tan^2 (the frustum's half diagonal). Shared edges are found by
// welding chart corners (and edge midpoints, for the quad sub-faces of n-gons) and take
// the larger rate of their two sides, so both sides place the same vertices there:
// OpenSubdiv's Bfr::Tessellation then triangulates each chart with its four edge rates
// and two inner rates. Boundary vertices are welded into shared positions. Closed
// surfaces drop patches that face away from every viewpoint in the range.
//
// The range's viewpoints form a spherical-shell sector around the object's centre (within
// `angle` of the representative direction, at distances within `distance_factor`);
// distances and facing are measured exactly against that set. A chart too large for one
// rate (a ground plane reaching the camera) is split: every chart of the object is cut
// into 2^d x 2^d patches, the same d throughout so shared edges still split alike.
//
// The view direction is part of the range too (it may turn by `angle`): a patch is dropped
// when, from the representative eye, it lies outside the frustum widened by that angle
// and by the parallax the eye's movement within the range can cause. A facet budget per
// object bounds the worst case: beyond it every rate is scaled by the same factor, which
// keeps shared edges matched but breaks the bound, and is counted.
#pragma once

#include <vector>

#include "geometry/surface.h"
#include "phases/facet_mesh.h"
#include "scene/scene.h"

namespace mpshade {

enum class DicingTarget {
    EdgeLength,  // projected edges at most maxEdgePixels
    Flatness,    // deviation from the surface at most flatnessPixels
};

struct DicingOptions {
    DicingTarget target = DicingTarget::EdgeLength;
    float maxEdgePixels = 0.5f;    // P/2: the bound on every facet edge (EdgeLength)
    float flatnessPixels = 0.25f;  // the bound on every facet's deviation (Flatness)
    // Measure at the closest any eye of the range comes (true), or at the representative
    // eye only (false).
    bool overRange = true;
    int maxEdgeRate = 256;     // per patch edge; charts split into patches to stay under it
    int maxSplitDepth = 6;     // charts split into at most 2^6 x 2^6 patches
    int maxPatches = 1 << 14;  // per object
    size_t maxFacets =
        4'000'000;  // per object; beyond it every rate scales down alike (counted as capped)
    bool frustumCull = true;  // drop patches no view of the range can see
    // Flatness: whether facets must also keep interpolated chart coordinates on the surface
    // (a shader map is probed at them, or the shader reads u, v, s, t or dPdu, dPdv), so a
    // chord's midpoint counts its whole distance from the surface point at the mid chart
    // coordinates. False: inside a patch, where the surface is flat, only the distance along
    // its normal counts -- a flat chart's facets lie on it however its coordinates run --
    // while the patch's edges (silhouettes, chart borders) and curved parts, whose
    // interpolated normals shading reads, still count it whole.
    bool chartExact = true;
    // Survey the whole charts only: DicedSurface has estimatedFacets (from their rates,
    // uncapped) and the patch count, nothing else.
    bool surveyOnly = false;
};

// The representative view in the object's own coordinates.
struct DicingView {
    glm::vec3 eye{0.0f};
    float pixelsPerUnit =
        1000.0f;  // pixels per object unit at unit distance: (height / 2) / tan(fov_y / 2)
    float fovSlack = 1.5f;       // >= 1: off-axis projections stretch lengths up to this factor
    float nearDistance = 0.01f;  // the near plane, object units
    glm::vec3 forward{0.0f, 0.0f, -1.0f};  // unit view direction
    float halfDiagonalFov = 0.7f;          // radians: the frustum's half angle across its diagonal
    // The representative view's projection (object -> X, Y, W; x_px = X / W), and the near
    // plane's depth W. With `projects`, EdgeLength measured at the representative eye takes
    // the chords' projected lengths -- exact for that view, where the bound above also
    // counts foreshortening and the worst off-axis stretch -- for chords in front of the
    // near plane.
    bool projects = false;
    double screen[3][4] = {};
    double nearW = 0.0;
};

struct DicedSurface {
    FixedPointFormat format;
    std::vector<uint16_t> qx, qy, qz;
    std::vector<ChartPoint> attributePoints;  // one per attribute vertex
    std::vector<SurfaceSample> attributeGeometry;
    std::vector<uint32_t> positionOf;    // attribute vertex -> position
    std::vector<uint32_t> triangles;     // attribute vertex indices, 3 per facet
    std::vector<FacetCluster> clusters;  // one per tessellated patch
    int charts = 0, patches = 0, culledCharts = 0,
        cappedCharts = 0;          // culled and capped count patches
    int frustumCulled = 0;         // patches outside every view of the range
    float rateScale = 1.0f;        // < 1 when the facet budget cut every rate
    double estimatedFacets = 0.0;  // from the surveyed rates, before the budget
};

DicedSurface diceSurface(const Surface& surface, const DicingView& view, const RangeOptions& range,
                         const DicingOptions& options = {});

}  // namespace mpshade
