// facet_rasterizer.h -- the dynamic TSI's sampling: warped facets to sub-pixel samples.
//
// Watertight: edge functions are evaluated exactly in int64 on 8-bit sub-pixel
// coordinates (|x| < 2^23, so products stay under 2^47), and a sample exactly on an edge
// belongs to exactly one of the two facets sharing it (a tie rule on the edge direction
// that is true for one direction and false for the other, like Direct3D's top-left rule).
// Since neighbouring facets share the very same warped vertices, no sample falls between
// them. Each sample keeps its nearest `layers` fragments in depth order (a k-buffer), cut
// short behind the first opaque one, so translucent surfaces composite front to back.
// Screen tiles are rasterized in parallel.
#pragma once

#include <cstdint>
#include <vector>

#include "phases/facet_mesh.h"
#include "phases/fixed_point_warp.h"
#include "phases/sample_pattern.h"

namespace mpshade {

struct Fragment {
    float depth;      // view depth (world units)
    uint32_t object;  // index in the frame's object list
    uint32_t facet;
    float b1, b2;  // perspective-correct weights of the facet's corners 1 and 2
    uint32_t opaque;
};

struct FragmentBuffer {
    int width = 0, height = 0, spp = 1, layers = 4;
    std::vector<Fragment> fragments;  // layers per sample, sample order as SampleBuffer
    std::vector<uint8_t> count;       // fragments kept per sample
    void resize(int w, int h, int samplesPerPixel, int k);
};

struct RasterObject {
    const FacetMesh* mesh = nullptr;
    const WarpedVertices* warped = nullptr;
    bool opaque = true;
    // Skip facets that face away from the eye: only for closed, opaque surfaces, whose
    // back faces are always behind a front face.
    bool cullBackFaces = false;
    // Per cluster of the mesh: 0 skips the cluster's facets entirely (null: all visible).
    const uint8_t* clusterVisible = nullptr;
};

struct RasterStats {
    uint64_t facets = 0;            // offered
    uint64_t facetsCulled = 0;      // a vertex behind the near plane or outside the guard band
    uint64_t facetsDegenerate = 0;  // zero area on the sub-pixel grid
    uint64_t facetsBackFacing = 0;  // culled as back faces of closed opaque surfaces
    uint64_t facetsInCulledClusters = 0;  // skipped with their whole cluster
    uint64_t facetsBinned = 0;            // facet-tile pairs rasterized
    uint64_t fragments = 0;               // sample hits kept or tested into the k-buffer
    uint64_t droppedLayers = 0;           // translucent fragments beyond the k-buffer's depth
};

struct RasterOptions {
    int tileSize = 16;  // pixels
    int layers = 4;     // fragments kept per sample
};

// `samples` supplies the sample positions (its xy); `out` receives the fragments.
void rasterizeFacets(const std::vector<RasterObject>& objects, const SampleBuffer& samples,
                     const RasterOptions& options, FragmentBuffer& out, RasterStats& stats);

}  // namespace mpshade
