// sample_depth_test.h -- the rasterizer's inner loop (facet_rasterizer.h): rows of sub-pixel
// samples tested against one facet's edge functions and depth plane, the nearest surface
// kept per sample (one layer, opaque objects).
//
// Several builds of one loop, chosen at run time: the compiler's vectorization for the
// baseline, AVX2 and AVX-512, and the loop by hand in AVX2 and in AVX-512 for the rows a
// facet a few pixels across gives (4-16 samples), where the compiled loop spends its time
// in its tail and in spilled registers. Every build does the same arithmetic in the same
// order -- edge values exact integers in double, the depth plane unfused -- so a sample's
// depth and facet are the same bits on any machine.
#pragma once

#include <cstddef>
#include <cstdint>

namespace mpshade {

// The tie rule: a sample exactly on edge (dx, dy) is inside for this direction and not for
// the reverse, so a shared edge's samples go to exactly one facet (folded into an edge
// function's constant as +1 where the facet owns the edge).
inline bool ownsEdge(int64_t dx, int64_t dy) {
    return dy > 0 || (dy == 0 && dx < 0);
}

// A facet's edge functions and depth relative to a tile's origin, in 1/256 pixels:
// e_i(lx, ly) = c_i + a_i lx + b_i ly, inside when every e_i > 0 (the watertight tie rule is
// folded into c_i); 1 / depth = zc + zx lx + zy ly. Every edge value is an exact integer
// below 2^53 in double.
struct FacetEdges {
    double c[3], a[3], b[3];
    double zc, zx, zy;
};

// `rows` runs of `n` samples, `stride` apart in every array: sample positions (fx, fy, in
// 1/256 pixels) and the frame's nearest surface so far per sample (1 / depth, object, facet),
// updated in place. Only samples [r * stride, r * stride + n) are read or written.
struct SampleRows {
    const int32_t* fx = nullptr;
    const int32_t* fy = nullptr;
    float* invDepth = nullptr;
    uint32_t* object = nullptr;
    uint32_t* facet = nullptr;
    size_t rows = 0, n = 0, stride = 0;
};

// What a facet-tile pair needs: the tile's origin (1/256 pixels), whether the edges are
// tested (false: the tile lies wholly inside the facet), and the ids written where it is
// nearest.
struct DepthTestFacet {
    const FacetEdges* edges = nullptr;
    int32_t ox = 0, oy = 0;
    bool testEdges = true;
    uint32_t object = 0, facet = 0;
};

enum class DepthTestKernel {
    Compiled,  // the compiler's vectorization, cloned for AVX-512, AVX2 and the baseline
    Avx2,      // by hand, four samples a vector
    Avx512,    // by hand, eight samples a vector, the tail masked
};

bool depthTestKernelAvailable(DepthTestKernel kernel);

// The samples inside the facet (all of them when !testEdges), each whose depth is nearer
// than its sample's taking the facet. The fastest kernel the processor has for rows of n.
uint32_t depthTestRows(const SampleRows& rows, const DepthTestFacet& facet);

// The same with a given kernel (tests and benchmarks); it must be available.
uint32_t depthTestRowsWith(DepthTestKernel kernel, const SampleRows& rows,
                           const DepthTestFacet& facet);

}  // namespace mpshade
