// facet_rasterizer.h -- the dynamic TSI's sampling: warped facets to a visibility buffer
// (which facet of which object each sub-pixel sample sees; Burns and Hunt 2013). What the
// surface looks like there -- barycentric weights, the n-tuple, shading -- is worked out
// later, once per visible surface, not for every facet a sample is tested against.
//
// Watertight: edge functions are exact integers on 8-bit sub-pixel coordinates (|x| <=
// 2^23, so each is below 2^51), and a sample exactly on an edge belongs to exactly one of
// the two facets sharing it (a tie rule on the edge direction, true for one direction and
// false for the other, like Direct3D's top-left rule). Neighbouring facets share the very
// same warped vertices (facets crossing the near plane or the guard band are clipped with
// shared crossings, facet_clipping.h), so no sample falls between them.
//
// Speed: the screen is cut into tiles rasterized in parallel; facets are binned into them
// in fixed chunks (deterministic order). Within a tile, a facet's edge functions and
// depth are evaluated for a row of samples at a time in double lanes (exact for these
// integers, and vectorized: AVX2 where the CPU has it, chosen at run time, SSE2
// otherwise); a tile a facet covers whole skips the edge tests. A facet whose box is at most
// kSmallFacetPixels on a side (most of them) is tested in float lanes instead, eight samples a
// vector, exact there (small_facet_depth_test.h). Each sample keeps its
// nearest `layers` surfaces in depth order (a k-buffer) cut short behind the first opaque
// one; with every object opaque, one layer and a plain depth test.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <vector>

#include "phases/facet_clipping.h"
#include "phases/facet_mesh.h"
#include "phases/fixed_point_warp.h"
#include "phases/sample_pattern.h"

namespace mpshade {

struct RasterObject {
    const FacetMesh* mesh = nullptr;  // null: nothing to draw
    const WarpedVertices* warped = nullptr;
    // Clips facets with a corner the warp culled; null: such facets are dropped.
    const FixedPointWarp* warp = nullptr;
    bool opaque = true;
    // Skip facets that face away from the eye: only for closed, opaque surfaces, whose
    // back faces are always behind a front face.
    bool cullBackFaces = false;
    // Per cluster of the mesh: 0 skips the cluster's facets entirely (null: all visible).
    const uint8_t* clusterVisible = nullptr;
    // If set: receives the longest projected edge, in pixels, of the facets offered (those
    // of visible clusters, clipped ones excepted).
    float* longestEdgePixels = nullptr;
};

// What each sample sees: up to `layers` surfaces, nearest first.
struct VisibilityBuffer {
    int width = 0, height = 0, spp = 1, layers = 1;
    std::vector<uint8_t> count;  // surfaces kept per sample
    // `layers` slots per sample: slot sample * layers + l. Only a sample's first count[s]
    // slots hold surfaces; the others' values are unspecified.
    std::vector<float> invDepth;  // 1 / view depth (world units)
    std::vector<uint32_t> object, facet;
    void resize(int w, int h, int samplesPerPixel, int k);
};

struct RasterStats {
    uint64_t facets = 0;                  // offered
    uint64_t facetsCulled = 0;            // wholly behind the near plane or outside the guard band
    uint64_t facetsClipped = 0;           // crossing the near plane or the guard band: clipped
    uint64_t facetsDegenerate = 0;        // zero area on the sub-pixel grid
    uint64_t facetsBackFacing = 0;        // culled as back faces of closed opaque surfaces
    uint64_t facetsInCulledClusters = 0;  // skipped with their whole cluster
    uint64_t facetsBinned = 0;            // facet-tile pairs rasterized
    uint64_t tilesCoveredWhole = 0;       // facet-tile pairs that skipped the edge tests
    uint64_t fragments = 0;               // sample hits tested against the depth buffer
    uint64_t droppedLayers = 0;           // translucent surfaces beyond the k-buffer's depth
    bool abandoned = false;  // RasterOptions::deadline passed: the buffer is incomplete

    RasterStats& operator+=(const RasterStats& o) {
        facets += o.facets;
        facetsCulled += o.facetsCulled;
        facetsClipped += o.facetsClipped;
        facetsDegenerate += o.facetsDegenerate;
        facetsBackFacing += o.facetsBackFacing;
        facetsInCulledClusters += o.facetsInCulledClusters;
        facetsBinned += o.facetsBinned;
        tilesCoveredWhole += o.tilesCoveredWhole;
        fragments += o.fragments;
        droppedLayers += o.droppedLayers;
        abandoned = abandoned || o.abandoned;
        return *this;
    }
};

struct RasterOptions {
    // Pixels per side of a tile, the unit of parallel work. Against 16, 32 rasterized the
    // courtyard, gallery and teapot 3-13% faster (fewer facets binned to two tiles; 240x135
    // to 1280x720) and the vase within noise; 8 was slower, and 64 no faster than 32 with
    // fewer tiles to share between threads.
    int tileSize = 32;
    int layers = 4;  // surfaces kept per sample when some object is translucent
    // Past this moment the chunks not yet binned and the tiles not yet drawn are skipped
    // and RasterStats::abandoned is set: the visibility buffer is then unusable. For work
    // that is worth less than a deadline (a prediction in a frame's slack); default never.
    std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();
};

// Keeps its bins and tile buffers from frame to frame, so a steady frame allocates nothing.
class FacetRasterizer {
  public:
    FacetRasterizer();
    ~FacetRasterizer();
    FacetRasterizer(const FacetRasterizer&) = delete;
    FacetRasterizer& operator=(const FacetRasterizer&) = delete;

    // farDepth: the far plane's view depth (world units); surfaces beyond it are not seen.
    void rasterize(const std::vector<RasterObject>& objects, const SampleLayout& samples,
                   float farDepth, const RasterOptions& options, VisibilityBuffer& out,
                   RasterStats& stats);

  private:
    struct State;
    std::unique_ptr<State> state_;
};

// One-off convenience: a rasterizer of its own.
void rasterizeFacets(const std::vector<RasterObject>& objects, const SampleLayout& samples,
                     float farDepth, const RasterOptions& options, VisibilityBuffer& out,
                     RasterStats& stats);

}  // namespace mpshade
