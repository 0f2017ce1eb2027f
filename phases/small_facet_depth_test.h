// small_facet_depth_test.h -- the rasterizer's inner loop for small facets (most facets a
// static phase dices: a pixel or a few across) in eight float lanes rather than four double
// ones (sample_depth_test.h, which larger facets keep).
//
// Exactness: the edge functions are taken relative to the corner of the facet's box of
// pixels, at most kSmallFacetPixels on a side, i.e. M = 256 kSmallFacetPixels sub-pixel
// units. Every vertex and every sample tested lies in the box (a sample of pixel p is at most
// at 256 (p + 1)), so an edge function's value at a sample, e = dx (y - yj) - dy (x - xj) + tie,
// is below 2 M^2 + 1 = 2^23 + 1 in magnitude, and so are its partial sums (values of e at
// points of the box) and products: all are integers a float holds exactly, so float lanes,
// fused or not, give the very signs int64 arithmetic gives and the watertight tie rule holds.
//
// Depth: the plane 1 / z = zc + zx lx + zy ly in float, unfused, in this order, by every
// build: a sample's depth is the same bits on any machine (they differ from the double
// plane's of large facets by a rounding; the depth test only compares them).
#pragma once

#include <cstddef>
#include <cstdint>

#include "phases/sample_depth_test.h"

namespace mpshade {

// Pixels on a side of the largest facet box taken in float lanes (see above: 2 M^2 + 1 must
// stay below 2^24).
inline constexpr int kSmallFacetPixels = 8;

// A small facet's edge functions and depth plane in float, relative to the corner (ox, oy) of
// its box of pixels, in 1/256 pixels: e_i = c_i + a_i lx + b_i ly, inside when every e_i > 0
// (the tie rule folded into c_i).
struct SmallFacetEdges {
    float c[3], a[3], b[3];
    float zc, zx, zy;
    int32_t ox = 0, oy = 0;
};

// The edges and depth plane of the facet with corners (x[i], y[i]) (1/256 pixels) and 1 /
// depth w[i], relative to the corner (ox, oy) of its box of pixels, which must be at most
// kSmallFacetPixels on a side.
SmallFacetEdges smallFacetEdges(const int32_t x[3], const int32_t y[3], const float w[3],
                                int32_t ox, int32_t oy);

// One sample at (lx, ly) from the box's corner, as every kernel does it: whether it is inside
// (the edges exact), and its 1 / depth (the plane unfused, in this order).
inline bool smallFacetInside(const SmallFacetEdges& s, float lx, float ly) {
    return (s.c[0] + s.a[0] * lx + s.b[0] * ly > 0.0f) &
           (s.c[1] + s.a[1] * lx + s.b[1] * ly > 0.0f) &
           (s.c[2] + s.a[2] * lx + s.b[2] * ly > 0.0f);
}
inline float smallFacetDepth(const SmallFacetEdges& s, float lx, float ly) {
    return s.zc + s.zx * lx + s.zy * ly;
}

enum class SmallFacetKernel {
    Compiled,  // plain float arithmetic the compiler vectorizes (every processor)
    Avx2,      // by hand, eight samples a vector (AVX2 and FMA)
};

bool smallFacetKernelAvailable(SmallFacetKernel kernel);

// As depthTestRows (sample_depth_test.h): the samples of `rows` inside the facet, each whose
// depth is nearer than its sample's taking the facet (object, facet); returns how many were
// inside. Every sample of `rows` must lie in the facet's box. The fastest kernel available.
uint32_t smallFacetDepthTest(const SampleRows& rows, const SmallFacetEdges& edges, uint32_t object,
                             uint32_t facet);
uint32_t smallFacetDepthTestWith(SmallFacetKernel kernel, const SampleRows& rows,
                                 const SmallFacetEdges& edges, uint32_t object, uint32_t facet);

}  // namespace mpshade
