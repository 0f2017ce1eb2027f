// feline_lanes.h -- Feline probes (probe.h) of several queries at once (eight in the AVX2
// build, four in the portable one), for the case that makes most of a frame's probes:
// consecutive queries (a facet's samples, pixel after pixel) that share one Feline setup.
// One at a time, a query cost about 370 instructions on the vase (callgrind, steady
// frames), nearly all of them bookkeeping: the footprint comparison, the line's bounds,
// the tile look-up and the bilinear weights of each tap. Here those run in vector lanes,
// and only the texel loads and their weighted sums go query by query.
//
// The lanes do each query's arithmetic in the order Prober::lineInTile does it (the taps
// stepped by repeated addition, the same products and sums in the same order); neither
// build has fused multiply-adds to contract one path's products and not the other's, so a
// query's n-tuple is the same bits whichever path and build probed it. Internal linkage,
// as prober.h explains.
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>

#include "shadermaps/prober.h"

#if defined(__SSE__)
#include <immintrin.h>
#endif

namespace mpshade {
// NOLINTNEXTLINE(cert-dcl59-cpp,google-build-namespaces): internal linkage on purpose (prober.h)
namespace {

// A Feline setup: what a query's footprint decides (probe_batch.h makes it), kept for the
// queries after it whose footprints are within `tolerance` of `derivatives`.
struct FelineSetup {
    int chart = -1;
    Float4 derivatives = {};  // dudx, dvdx, dudy, dvdy
    float tolerance = -1.0f;  // no query shares the setup before the first
    int n = 1, l0 = 0, l1 = 0;
    float blend = 0.0f, offsetU = 0.0f, offsetV = 0.0f, du = 0.0f, dv = 0.0f;
    float weights[kMaxTaps] = {};
};

// A query's footprint (dudx, dvdx, dudy, dvdy) as one vector.
inline Float4 queryDerivatives(const ProbeQuery& q) {
    static_assert(offsetof(ProbeQuery, dvdx) == offsetof(ProbeQuery, dudx) + sizeof(float) &&
                  offsetof(ProbeQuery, dudy) == offsetof(ProbeQuery, dudx) + 2 * sizeof(float) &&
                  offsetof(ProbeQuery, dvdy) == offsetof(ProbeQuery, dudx) + 3 * sizeof(float));
    Float4 v;
    std::memcpy(&v, reinterpret_cast<const char*>(&q) + offsetof(ProbeQuery, dudx), sizeof v);
    return v;
}

// Whether a query's footprint shares `setup` (|change| <= tolerance in all four, false for a
// NaN either way).
inline bool sharesSetup(const FelineSetup& setup, const ProbeQuery& q) {
    const Float4 change = queryDerivatives(q) - setup.derivatives;
    // |change| by clearing the sign bits; NaN stays NaN, and compares false.
    const Float4 size = reinterpret_cast<Float4>(reinterpret_cast<Int4>(change) & 0x7fffffff);
    const auto within = size <= setup.tolerance;
#if defined(__SSE__)
    const bool all = _mm_movemask_ps(reinterpret_cast<__m128>(within)) == 0xF;
#else
    const bool all = (within[0] & within[1] & within[2] & within[3]) != 0;
#endif
    return q.chart == setup.chart && all;
}

// As many lanes as the build's vectors hold: GCC splits a vector wider than the
// instruction set's, and compares its floats lane by lane (the portable build's eight
// lanes cost more than they saved).
#if defined(MPSHADE_PROBE_LANES)
constexpr int kLanes = MPSHADE_PROBE_LANES;  // a file built for wider vectors says so
#else
constexpr int kLanes = 4;
#endif
using LaneFloats = float __attribute__((vector_size(4 * kLanes)));
using LaneInts = int32_t __attribute__((vector_size(4 * kLanes)));

// The lanes of a mask as bits, lane j at bit j.
inline unsigned laneBits(LaneInts mask) {
#if defined(MPSHADE_PROBE_LANES) && MPSHADE_PROBE_LANES == 8
    return static_cast<unsigned>(_mm256_movemask_ps(reinterpret_cast<__m256>(mask)));
#elif defined(__SSE__) && !defined(MPSHADE_PROBE_LANES)
    return static_cast<unsigned>(_mm_movemask_ps(reinterpret_cast<__m128>(mask)));
#else
    unsigned bits = 0;
    for (int j = 0; j < kLanes; ++j) bits |= (mask[j] != 0 ? 1u : 0u) << j;
    return bits;
#endif
}

// Probes the first queries of q[0 .. m - 1] (m <= kLanes) by Feline with `setup` into value[j]
// (channels 0 .. C - 1 of query j): as many, from the first, as share the setup, have
// each line inside its level (no tap clamped) and read resident tiles within one tile of
// the first query's first tap. Each tap reads the tile its texel lies in (its 2x2 texels
// are in that tile's storage, border included). Returns how many were probed; 0: the first
// is for the one-at-a-time path.
template <int C, typename Texels>
int felineLanes(const Prober<C, Texels>& p, const FelineSetup& setup, const ProbeQuery* q, int m,
                Float4 (*value)[Prober<C, Texels>::kVectors]) {
    using P = Prober<C, Texels>;
    using Storage = typename P::Storage;
    constexpr int kVectors = P::kVectors;
    static_assert(kVectors > 0, "lanes of queries hold up to 8 channels");
    LaneFloats u = {}, v = {};
    int lanes = 0;
    for (; lanes < m && sharesSetup(setup, q[lanes]); ++lanes)
        u[lanes] = q[lanes].u, v[lanes] = q[lanes].v;
    if (lanes == 0) return 0;
    // Lanes past the last are copies of it: what is true of it is true of them.
    for (int j = lanes; j < kLanes; ++j) u[j] = u[lanes - 1], v[j] = v[lanes - 1];
    // A non-finite coordinate reads the chart's origin (x - x is 0 for a finite x only).
    const LaneFloats zero = {};
    u = reinterpret_cast<LaneFloats>(reinterpret_cast<LaneInts>(u) & (u - u == zero));
    v = reinterpret_cast<LaneFloats>(reinterpret_cast<LaneInts>(v) & (v - v == zero));
    const LaneFloats u0 = u + setup.offsetU, v0 = v + setup.offsetV;

    // No member has a default initializer: a zeroed Line was a string store a call (five of
    // them with the sums below), each tens of cycles to start for a few hundred bytes.
    struct Line {
        int level;
        float scale, fu, fv, dx, dy;  // texels along u and v (chart_aspect.h)
        int tx0, ty0;                 // the tile of the first query's first tap
        const Storage* tiles[9];      // tiles tx0 - 1 .. tx0 + 1 by ty0 - 1 .. ty0 + 1: only
                                      // those a probed lane reads are set
    };
    Line lines[2];
    int count = 0;
    if (setup.blend < 1.0f)
        lines[count].level = setup.l0, lines[count++].scale = 1.0f - setup.blend;
    if (setup.blend > 0.0f) lines[count].level = setup.l1, lines[count++].scale = setup.blend;
    const int n = setup.n;
    const int shift = p.tileShift;
    for (int l = 0; l < count; ++l) {
        Line& line = lines[l];
        line.fu = p.resU(setup.chart, line.level), line.fv = p.resV(setup.chart, line.level);
        line.dx = setup.du * line.fu, line.dy = setup.dv * line.fv;
        const LaneFloats x0 = u0 * line.fu - 0.5f, y0 = v0 * line.fv - 0.5f;
        const LaneFloats xe = x0 + static_cast<float>(n - 1) * line.dx,
                         ye = y0 + static_cast<float>(n - 1) * line.dy;
        // Inside the level and away from its last texel (lineInTile's test): no tap is
        // clamped, and each floor is a truncation.
        const float lastU = line.fu - 1.0f, lastV = line.fv - 1.0f;
        const LaneInts inside = (x0 >= 0.0f) & (xe >= 0.0f) & (y0 >= 0.0f) & (ye >= 0.0f) &
                                (x0 < lastU) & (xe < lastU) & (y0 < lastV) & (ye < lastV);
        line.tx0 = static_cast<int>(x0[0]) >> shift, line.ty0 = static_cast<int>(y0[0]) >> shift;
        // Each tap's tile among the 3x3 around (tx0, ty0), as a bit per lane: the tiles the
        // lanes read are then looked up once each, whether the lanes' taps stay in one tile
        // or straddle two (a quarter of the vase's batches; looking their taps up lane by
        // lane had been a fifth of the lanes' instructions).
        LaneInts near = inside, used = {};
        const LaneInts one = LaneInts{} + 1, centre = LaneInts{} + 4;
        LaneFloats x = x0, y = y0;
        for (int i = 0; i < n; ++i, x += line.dx, y += line.dy) {
            const LaneInts dtx = (__builtin_convertvector(x, LaneInts) >> shift) - (line.tx0 - 1);
            const LaneInts dty = (__builtin_convertvector(y, LaneInts) >> shift) - (line.ty0 - 1);
            near &= (dtx >= 0) & (dtx <= 2) & (dty >= 0) & (dty <= 2);
            // A lane not near shifts by the centre's slot: never by an amount out of range.
            used |= one << (near ? dty * 3 + dtx : centre);
        }
        // The lanes from the first that are inside and near, then what they read.
        lanes = std::min(lanes, std::countr_one(laneBits(near)));
        unsigned wanted = 0;
        for (int j = 0; j < lanes; ++j) wanted |= static_cast<unsigned>(used[j]);
        unsigned missing = 0;
        for (unsigned bits = wanted; bits != 0; bits &= bits - 1) {
            const int slot = std::countr_zero(bits);
            line.tiles[slot] =
                p.tileAt(setup.chart, line.level, line.tx0 + slot % 3 - 1, line.ty0 + slot / 3 - 1);
            if (!line.tiles[slot]) missing |= 1u << slot;
        }
        if (missing != 0) {
            int ok = 0;
            while (ok < lanes && (static_cast<unsigned>(used[ok]) & missing) == 0) ++ok;
            lanes = ok;
        }
        if (lanes == 0) return 0;
    }

    // Texel offsets and bilinear weights in lanes, tap by tap, then each query's texels with
    // its sums in registers: lane j's line l adds its taps in order into acc, and acc into the
    // line sum, as lineInTile does.
    constexpr int kTapsAtOnce = 4;  // taps a pass keeps in lanes (n is nearly always 1-3)
    struct Tap {
        LaneInts slot, at;
        LaneFloats w00, w10, w01, w11;
    };
    const int rowValues = static_cast<int>(p.rowValues);
    const int border = p.border;
    for (int l = 0; l < count; ++l) {
        const Line& line = lines[l];
        LaneFloats x = u0 * line.fu - 0.5f, y = v0 * line.fv - 0.5f;
        // The first line sums straight into the caller's values (0 + acc is acc: a sum from +0
        // is never -0), the second apart and then added. Summed apart and copied there, the
        // copies (string moves of the lanes' vectors) were 6.6% of the probe's samples.
        Float4 second[kLanes][kVectors];
        Float4(*acc)[kVectors] = l == 0 ? value : second;
        for (int i0 = 0; i0 < n; i0 += kTapsAtOnce) {
            const int taps = std::min(kTapsAtOnce, n - i0);
            Tap tap[kTapsAtOnce];
            for (int t = 0; t < taps; ++t, x += line.dx, y += line.dy) {
                const LaneInts ix = __builtin_convertvector(x, LaneInts),
                               iy = __builtin_convertvector(y, LaneInts);
                const LaneFloats fx = x - __builtin_convertvector(ix, LaneFloats);
                const LaneFloats fy = y - __builtin_convertvector(iy, LaneFloats);
                const float wi = setup.weights[i0 + t] * line.scale;
                const LaneFloats wy0 = wi * (1.0f - fy), wy1 = wi * fy;
                tap[t].w00 = wy0 * (1.0f - fx), tap[t].w10 = wy0 * fx;
                tap[t].w01 = wy1 * (1.0f - fx), tap[t].w11 = wy1 * fx;
                const LaneInts tx = ix >> shift, ty = iy >> shift;
                tap[t].slot = (ty - line.ty0 + 1) * 3 + (tx - line.tx0 + 1);
                tap[t].at =
                    (iy - (ty << shift) + border) * rowValues + (ix - (tx << shift) + border) * C;
            }
            for (int j = 0; j < lanes; ++j) {
                Float4 a[kVectors];
                for (int k = 0; k < kVectors; ++k) a[k] = i0 == 0 ? Float4{} : acc[j][k];
                for (int t = 0; t < taps; ++t)
                    p.addTexels(line.tiles[tap[t].slot[j]] + tap[t].at[j], tap[t].w00[j],
                                tap[t].w10[j], tap[t].w01[j], tap[t].w11[j], a);
                for (int k = 0; k < kVectors; ++k) acc[j][k] = a[k];
            }
        }
        if (l > 0)
            for (int j = 0; j < lanes; ++j)
                for (int k = 0; k < kVectors; ++k) value[j][k] = value[j][k] + second[j][k];
    }
    p.fastProbes +=
        static_cast<uint64_t>(count) * static_cast<uint64_t>(n) * static_cast<uint64_t>(lanes);
    return lanes;
}

}  // namespace
}  // namespace mpshade
