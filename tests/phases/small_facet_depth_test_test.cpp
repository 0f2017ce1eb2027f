#include "phases/small_facet_depth_test.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <random>
#include <vector>

namespace mpshade {
namespace {

std::vector<SmallFacetKernel> availableKernels() {
    std::vector<SmallFacetKernel> k;
    for (SmallFacetKernel kernel : {SmallFacetKernel::Compiled, SmallFacetKernel::Avx2})
        if (smallFacetKernelAvailable(kernel)) k.push_back(kernel);
    return k;
}

uint32_t bitsOf(float x) {
    uint32_t b;
    std::memcpy(&b, &x, sizeof b);
    return b;
}

// Integer edge functions e_k = c_k + a_k lx + b_k ly, tested in int64 here and handed to the
// kernels as floats (exact for the magnitudes each test uses).
struct IntEdges {
    int64_t c[3], a[3], b[3];
    SmallFacetEdges asFloats(int32_t ox, int32_t oy, float zc, float zx, float zy) const {
        SmallFacetEdges s;
        for (int k = 0; k < 3; ++k) {
            s.c[k] = static_cast<float>(c[k]);
            s.a[k] = static_cast<float>(a[k]);
            s.b[k] = static_cast<float>(b[k]);
        }
        s.zc = zc, s.zx = zx, s.zy = zy, s.ox = ox, s.oy = oy;
        return s;
    }
};

struct Case {
    size_t rows, n, stride;
    std::vector<int32_t> fx, fy;
    std::vector<float> inv0;
};

// Runs every kernel and the dispatcher on `c` and checks each against exact int64 edges and
// the plane written out in float, unfused, in the kernels' order: the same count, and the
// same bits of depth, object and facet for every sample (the gaps between rows untouched).
void expectExact(const Case& c, const IntEdges& e, const SmallFacetEdges& s, const char* what) {
    const size_t total = c.rows * c.stride;
    std::vector<float> inv = c.inv0;
    std::vector<uint32_t> object(total, 0xAAAAAAAAu), facet(total, 0xBBBBBBBBu);
    uint32_t inside = 0;
    for (size_t r = 0; r < c.rows; ++r)
        for (size_t i = r * c.stride; i < r * c.stride + c.n; ++i) {
            const int64_t lx = c.fx[i] - s.ox, ly = c.fy[i] - s.oy;
            bool in = true;
            for (int k = 0; k < 3; ++k) in = in && e.c[k] + e.a[k] * lx + e.b[k] * ly > 0;
            const float fx = static_cast<float>(lx), fy = static_cast<float>(ly);
            const float partial = s.zc + s.zx * fx;
            const float z = partial + s.zy * fy;
            inside += in;
            if (in && z > inv[i]) inv[i] = z, object[i] = 5, facet[i] = 9;
        }
    std::vector<SmallFacetKernel> kernels = availableKernels();
    for (size_t k = 0; k <= kernels.size(); ++k) {
        std::vector<float> gotInv = c.inv0;
        std::vector<uint32_t> gotObject(total, 0xAAAAAAAAu), gotFacet(total, 0xBBBBBBBBu);
        const SampleRows sr{c.fx.data(),     c.fy.data(), gotInv.data(), gotObject.data(),
                            gotFacet.data(), c.rows,      c.n,           c.stride};
        // The last round is the dispatcher's choice.
        const uint32_t got = k < kernels.size() ? smallFacetDepthTestWith(kernels[k], sr, s, 5, 9)
                                                : smallFacetDepthTest(sr, s, 5, 9);
        ASSERT_EQ(got, inside) << what << ", kernel " << k;
        for (size_t i = 0; i < total; ++i) {
            ASSERT_EQ(bitsOf(gotInv[i]), bitsOf(inv[i])) << what << ", kernel " << k << ", " << i;
            ASSERT_EQ(gotObject[i], object[i]) << what << ", kernel " << k << ", " << i;
            ASSERT_EQ(gotFacet[i], facet[i]) << what << ", kernel " << k << ", " << i;
        }
    }
}

// Many samples exactly on an edge (e = 0 is outside: the tie rule is folded into c) or one
// unit from it, rows of every length 1-40 (the vector loops, the four-sample step and the
// scalar tail), facets covering part of their rows.
TEST(SmallFacetDepthTest, EveryKernelMatchesExactEdgesOnTheBoundary) {
    std::mt19937 rng(11);
    std::uniform_int_distribution<int> pos(0, 60), coef(-4, 4), offset(-96, 96), len(1, 40);
    std::uniform_real_distribution<float> depth(0.0f, 1.0f);
    int onEdge = 0, partial = 0;
    for (int trial = 0; trial < 400; ++trial) {
        Case c;
        c.rows = 1 + trial % 3;
        c.n = static_cast<size_t>(len(rng));
        c.stride = c.n + 1 + static_cast<size_t>(trial % 5);
        const size_t total = c.rows * c.stride;
        c.fx.resize(total), c.fy.resize(total), c.inv0.resize(total);
        const int32_t ox = trial % 7, oy = trial % 5;
        for (size_t i = 0; i < total; ++i) {
            c.fx[i] = ox + pos(rng), c.fy[i] = oy + pos(rng);
            c.inv0[i] = depth(rng);
        }
        IntEdges e;
        for (int k = 0; k < 3; ++k) e.c[k] = offset(rng), e.a[k] = coef(rng), e.b[k] = coef(rng);
        const SmallFacetEdges s = e.asFloats(ox, oy, 0.5f, 1e-3f / 3.0f, -1e-3f / 7.0f);
        uint32_t inside = 0;
        for (size_t r = 0; r < c.rows; ++r)
            for (size_t i = r * c.stride; i < r * c.stride + c.n; ++i) {
                bool in = true;
                for (int k = 0; k < 3; ++k) {
                    const int64_t v = e.c[k] + e.a[k] * (c.fx[i] - ox) + e.b[k] * (c.fy[i] - oy);
                    onEdge += v == 0;
                    in = in && v > 0;
                }
                inside += in;
            }
        partial += inside > 0 && inside < c.rows * c.n;
        expectExact(c, e, s, "lattice");
    }
    EXPECT_GT(onEdge, 100);
    EXPECT_GT(partial, 100);
}

// Samples near the corner (m, m - 1) of a box m units on a side, on and around the edge
// e = m ly - (m - 1) lx from (0, 0) to that corner: at step t back along the edge and dy
// across it, e = m dy - t, so e = 0, -1, ..., -7 and values m units either side.
std::vector<std::pair<int64_t, int64_t>> cornerSamples(int64_t m) {
    std::vector<std::pair<int64_t, int64_t>> xy;
    for (int64_t t = 0; t < 8; ++t)
        for (int64_t dy = -1; dy <= 1; ++dy) xy.emplace_back(m - t, m - 1 - t + dy);
    return xy;
}

// The exactness bound at its own value: a sliver along the diagonal of the largest box the
// rasterizer hands these kernels (kSmallFacetPixels on a side), its samples on the edge and
// beside it at the far corner, where the partial sums c + a lx are largest.
TEST(SmallFacetDepthTest, EdgesStayExactAtTheLargestBox) {
    const int64_t m = 256 * kSmallFacetPixels;
    // The other two edges keep the whole box inside, so only this one decides.
    IntEdges e;
    e.c[0] = 0, e.a[0] = -(m - 1), e.b[0] = m;
    for (int k = 1; k < 3; ++k) e.c[k] = 4 * m * m, e.a[k] = 1, e.b[k] = 1;
    Case c;
    for (const auto& [lx, ly] : cornerSamples(m)) {
        c.fx.push_back(static_cast<int32_t>(lx));
        c.fy.push_back(static_cast<int32_t>(ly));
        c.inv0.push_back(0.0f);
    }
    c.rows = 1, c.n = c.fx.size(), c.stride = c.n;
    expectExact(c, e, e.asFloats(0, 0, 0.25f, 0.0f, 0.0f), "largest box");

    // The test's teeth: in a box four times as large the same arithmetic in float (what the
    // kernels do) misjudges some of these samples, whose partial sums pass 2^24.
    const int64_t big = 4 * m;
    int wrong = 0;
    for (const auto& [lx, ly] : cornerSamples(big)) {
        const int64_t exact = big * ly - (big - 1) * lx;
        const float partial = static_cast<float>(-(big - 1)) * static_cast<float>(lx);
        const float value = partial + static_cast<float>(big) * static_cast<float>(ly);
        wrong += (value > 0.0f) != (exact > 0) ||
                 static_cast<double>(value) != static_cast<double>(exact);
    }
    EXPECT_GT(wrong, 0);
}

// The setup against the triangle's own numbers: in either winding, each edge function is
// twice the facet's area at its opposite corner and zero at the other two (plus one where the
// facet owns the edge, by the tie rule), and the depth plane gives each corner's 1 / depth.
TEST(SmallFacetDepthTest, SetupReproducesTheCorners) {
    const int32_t ox = -512, oy = 768;  // the box's corner, 1/256 pixels
    const int32_t x[3] = {ox + 100, ox + 1900, ox + 37}, y[3] = {oy + 5, oy + 800, oy + 2040};
    const float w[3] = {0.5f, 0.25f, 0.125f};
    const int64_t area2 =
        std::abs(int64_t{x[1] - x[0]} * (y[2] - y[0]) - int64_t{y[1] - y[0]} * (x[2] - x[0]));
    for (int winding = 0; winding < 2; ++winding) {
        const int p[3] = {0, winding ? 2 : 1, winding ? 1 : 2};
        const int32_t px[3] = {x[p[0]], x[p[1]], x[p[2]]}, py[3] = {y[p[0]], y[p[1]], y[p[2]]};
        const float pw[3] = {w[p[0]], w[p[1]], w[p[2]]};
        const SmallFacetEdges s = smallFacetEdges(px, py, pw, ox, oy);
        EXPECT_EQ(s.ox, ox);
        EXPECT_EQ(s.oy, oy);
        for (int v = 0; v < 3; ++v) {
            const float lx = static_cast<float>(x[v] - ox), ly = static_cast<float>(y[v] - oy);
            int atCorner = 0;
            for (int k = 0; k < 3; ++k) {
                const float e = s.c[k] + s.a[k] * lx + s.b[k] * ly;
                // Whatever the edge's tie, e is 0 or 1 away from the corner's own edge.
                if (e >= 2.0f) {
                    EXPECT_TRUE(e == static_cast<float>(area2) ||
                                e == static_cast<float>(area2 + 1))
                        << e;
                    ++atCorner;
                } else {
                    EXPECT_TRUE(e == 0.0f || e == 1.0f) << e;
                }
            }
            EXPECT_EQ(atCorner, 1) << "corner " << v;
            EXPECT_NEAR(smallFacetDepth(s, lx, ly), w[v], 1e-6f) << "corner " << v;
        }
    }
}

}  // namespace
}  // namespace mpshade
