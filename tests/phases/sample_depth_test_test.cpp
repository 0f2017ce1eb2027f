#include "phases/sample_depth_test.h"

#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <vector>

namespace mpshade {
namespace {

std::vector<DepthTestKernel> availableKernels() {
    std::vector<DepthTestKernel> k;
    for (DepthTestKernel kernel :
         {DepthTestKernel::Compiled, DepthTestKernel::Avx2, DepthTestKernel::Avx512})
        if (depthTestKernelAvailable(kernel)) k.push_back(kernel);
    return k;
}

uint32_t bitsOf(float x) {
    uint32_t b;
    std::memcpy(&b, &x, sizeof b);
    return b;
}

// Rows of samples on a small integer lattice and integer edge functions with small
// coefficients, so many samples lie exactly on an edge (e = 0: outside, the tie rule being
// folded into c) or one unit either side of it. Each kernel must give what exact int64
// arithmetic gives, write only the samples of its rows (the gaps between rows hold
// sentinels), keep the nearer depth, and count the samples inside.
TEST(SampleDepthTest, EveryKernelMatchesExactEdgesOnTheBoundary) {
    std::mt19937 rng(7);
    std::uniform_int_distribution<int> pos(-40, 40), coef(-4, 4), offset(-96, 96), len(1, 70);
    std::uniform_real_distribution<float> depth(0.0f, 1.0f);
    int onEdge = 0, partial = 0;
    for (int trial = 0; trial < 400; ++trial) {
        const size_t rows = 1 + trial % 3, n = static_cast<size_t>(len(rng)),
                     stride = n + 1 + static_cast<size_t>(trial % 5);
        const size_t total = rows * stride;
        std::vector<int32_t> fx(total), fy(total);
        for (size_t i = 0; i < total; ++i) fx[i] = pos(rng), fy[i] = pos(rng);
        int64_t c[3], a[3], b[3];
        FacetEdges e;
        for (int k = 0; k < 3; ++k) {
            c[k] = offset(rng), a[k] = coef(rng), b[k] = coef(rng);
            e.c[k] = static_cast<double>(c[k]);
            e.a[k] = static_cast<double>(a[k]);
            e.b[k] = static_cast<double>(b[k]);
        }
        e.zc = 0.5, e.zx = 1.0 / 3.0 * 1e-3, e.zy = -1.0 / 7.0 * 1e-3;
        const int32_t ox = trial % 7 - 3, oy = trial % 5 - 2;
        const bool testEdges = trial % 4 != 3;
        std::vector<float> inv0(total);
        for (float& v : inv0) v = depth(rng);
        // Expected, by int64 edges and the plane's formula written out.
        std::vector<float> inv = inv0;
        std::vector<uint32_t> object(total, 0xAAAAAAAAu), facet(total, 0xBBBBBBBBu);
        uint32_t inside = 0;
        for (size_t r = 0; r < rows; ++r)
            for (size_t i = r * stride; i < r * stride + n; ++i) {
                const int64_t lx = fx[i] - ox, ly = fy[i] - oy;
                bool in = true;
                for (int k = 0; k < 3; ++k) {
                    const int64_t v = c[k] + a[k] * lx + b[k] * ly;
                    onEdge += v == 0;
                    in = in && (!testEdges || v > 0);
                }
                const double dz = e.zx * static_cast<double>(lx);
                const float z = static_cast<float>(e.zc + dz + e.zy * static_cast<double>(ly));
                inside += in;
                if (in && z > inv[i]) inv[i] = z, object[i] = 5, facet[i] = 9;
            }
        partial += inside > 0 && inside < rows * n;
        for (DepthTestKernel kernel : availableKernels()) {
            std::vector<float> gotInv = inv0;
            std::vector<uint32_t> gotObject(total, 0xAAAAAAAAu), gotFacet(total, 0xBBBBBBBBu);
            const SampleRows sr{
                fx.data(), fy.data(), gotInv.data(), gotObject.data(), gotFacet.data(),
                rows,      n,         stride};
            const uint32_t got = depthTestRowsWith(kernel, sr, {&e, ox, oy, testEdges, 5, 9});
            ASSERT_EQ(got, inside) << "kernel " << static_cast<int>(kernel) << ", trial " << trial;
            for (size_t i = 0; i < total; ++i) {
                ASSERT_EQ(bitsOf(gotInv[i]), bitsOf(inv[i]))
                    << "kernel " << static_cast<int>(kernel) << ", trial " << trial << ", sample "
                    << i;
                ASSERT_EQ(gotObject[i], object[i]) << static_cast<int>(kernel) << " " << i;
                ASSERT_EQ(gotFacet[i], facet[i]) << static_cast<int>(kernel) << " " << i;
            }
        }
        // The dispatcher gives the same as every kernel.
        std::vector<float> gotInv = inv0;
        std::vector<uint32_t> gotObject(total, 0xAAAAAAAAu), gotFacet(total, 0xBBBBBBBBu);
        EXPECT_EQ(depthTestRows({fx.data(), fy.data(), gotInv.data(), gotObject.data(),
                                 gotFacet.data(), rows, n, stride},
                                {&e, ox, oy, testEdges, 5, 9}),
                  inside);
        EXPECT_EQ(gotFacet, facet);
    }
    // The cases are the hard ones: exact zeros, and facets covering part of their rows.
    EXPECT_GT(onEdge, 200);
    EXPECT_GT(partial, 100);
}

}  // namespace
}  // namespace mpshade
