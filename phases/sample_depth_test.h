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
#include <type_traits>
#include <utility>

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

// A facet's edge functions (the tie rule folded in) and depth plane relative to (ox, oy), from
// its corners (xs[i], ys[i]) in 1/256 pixels and their 1 / depth ws[i]: the edges in Int,
// which must hold the corners' offsets from the origin and their products exactly (int64
// anywhere in the guard band; int32 within a small facet's box, small_facet_depth_test.h),
// the plane in double, both stored in Edges' own type (FacetEdges: double; SmallFacetEdges:
// float). Edge i runs from corner i + 1 to i + 2, opposite corner i; it is +area there.
// Inlined into each caller, as the two setups were before they shared this (out of line, the
// small facets' copy was a call of its own per facet-tile pair).
template <typename Int, typename Edges>
[[gnu::always_inline]] inline void setUpFacetEdges(const int32_t xs[3], const int32_t ys[3],
                                                   const float ws[3], Int ox, Int oy, Edges& s) {
    using Value = std::remove_reference_t<decltype(s.c[0])>;
    using Plane = std::remove_reference_t<decltype(s.zc)>;
    Int x[3], y[3];
    float w[3];
    for (int i = 0; i < 3; ++i) x[i] = Int{xs[i]} - ox, y[i] = Int{ys[i]} - oy, w[i] = ws[i];
    Int area = (x[1] - x[0]) * (y[2] - y[0]) - (y[1] - y[0]) * (x[2] - x[0]);
    if (area < 0) {
        std::swap(x[1], x[2]);
        std::swap(y[1], y[2]);
        std::swap(w[1], w[2]);
        area = -area;
    }
    const double invArea = 1.0 / static_cast<double>(area);
    double zc = 0.0, zx = 0.0, zy = 0.0;
    for (int i = 0; i < 3; ++i) {
        const int j = (i + 1) % 3, k = (i + 2) % 3;
        const Int dx = x[k] - x[j], dy = y[k] - y[j];
        const Int c = dy * x[j] - dx * y[j];
        s.c[i] = static_cast<Value>(c + (ownsEdge(dx, dy) ? 1 : 0));
        s.a[i] = static_cast<Value>(-dy);
        s.b[i] = static_cast<Value>(dx);
        zc += w[i] * static_cast<double>(c) * invArea;
        zx += w[i] * static_cast<double>(-dy) * invArea;
        zy += w[i] * static_cast<double>(dx) * invArea;
    }
    s.zc = static_cast<Plane>(zc), s.zx = static_cast<Plane>(zx), s.zy = static_cast<Plane>(zy);
}

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
