// noise_lanes.h -- the lane noise functions' body, for the files that build it for one
// instruction set each (noise_avx2.cpp, noise_avx512.cpp), included after their target
// switch. Everything here has internal linkage, so each file's copies are compiled for its
// own instruction set and none replaces another's at link time.
//
// Each lane computes exactly what snoise3 computes for it, operation for operation (no
// contraction into fused multiply-adds: the project builds with -ffp-contract=off, ISO
// C++'s default), so the values are the same bit for bit. Lanes whose input is not finite
// or whose lattice cell does not fit an int32 are left to snoise3. The vectors are GCC's
// vector extensions (Clang has them too) of W lanes; a Corners policy computes the eight
// corner hashes of W lattice cells, the only part that differs between the builds.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>

#include "shading/noise.h"
#include "shading/noise_paths.h"

namespace mpshade {
// NOLINTNEXTLINE(cert-dcl59-cpp,google-build-namespaces): internal linkage on purpose (above)
namespace {

#define MPSHADE_NOISE_INLINE [[gnu::always_inline]] inline

// floor(x) for |x| < 2^31 (exact: an integer-valued float) and its low byte.
template <class F, class I>
MPSHADE_NOISE_INLINE void latticeLanes(F x, I& cell, F& frac) {
    const I t = __builtin_convertvector(x, I);  // towards zero
    const F tf = __builtin_convertvector(t, F);
    const I below = tf > x;  // -1 where truncation rounded up
    const I f = t + below;
    // x - floor(x) rounded once to float, as snoise3's exact double difference is.
    frac = x - __builtin_convertvector(f, F);
    cell = f & 255;
}

template <class F>
MPSHADE_NOISE_INLINE F fadeLanes(F t) {
    return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f);
}

template <class F>
MPSHADE_NOISE_INLINE F lerpLanes(F t, F a, F b) {
    return a + t * (b - a);
}

// Perlin's gradient table row for each lane's hash (its low four bits), as selects.
template <class F, class I>
MPSHADE_NOISE_INLINE F gradLanes(I hash, F x, F y, F z) {
    const I h = hash & 15;
    const F zero = {}, one = zero + 1.0f;
    const F su = (h & 1) != 0 ? -one : one, sv = (h & 2) != 0 ? -one : one;
    const I vx = (h == 12) | (h == 14);
    const F gx = (h < 8 ? su : zero) + (vx != 0 ? sv : zero);
    const F gy = (h >= 8 ? su : zero) + (h < 4 ? sv : zero);
    const F gz = ((h >= 4) & ~vx) != 0 ? sv : zero;
    return gx * x + gy * y + gz * z;
}

// |x| < 2^30, so floor(x) fits an int32 (false for NaN and infinities): the lanes
// snoiseLanes computes as snoise3 does.
template <class F, class I>
MPSHADE_NOISE_INLINE I inLatticeRange(F x) {
    const I magnitude = (I)x & 0x7fffffff;
    const F limit = F{} + 0x1p30f;
    return (F)magnitude < limit;
}

// snoise3 of each lane; corners(X, Y, Z, h) writes the eight corners' hashes of the cells,
// corners.grad(h, x, y, z) is gradLanes' value; corners.all(mask) whether every lane is set.
template <class F, class I, class Corners>
MPSHADE_NOISE_INLINE F snoiseLanes(F x, F y, F z, const Corners& corners) {
    I X, Y, Z;
    latticeLanes(x, X, x);
    latticeLanes(y, Y, y);
    latticeLanes(z, Z, z);
    I h[8];
    corners(X, Y, Z, h);
    const F u = fadeLanes(x), v = fadeLanes(y), w = fadeLanes(z);
    const F x1 = x - 1.0f, y1 = y - 1.0f, z1 = z - 1.0f;
    const F r = lerpLanes(
        w,
        lerpLanes(v, lerpLanes(u, corners.grad(h[0], x, y, z), corners.grad(h[1], x1, y, z)),
                  lerpLanes(u, corners.grad(h[2], x, y1, z), corners.grad(h[3], x1, y1, z))),
        lerpLanes(v, lerpLanes(u, corners.grad(h[4], x, y, z1), corners.grad(h[5], x1, y, z1)),
                  lerpLanes(u, corners.grad(h[6], x, y1, z1), corners.grad(h[7], x1, y1, z1))));
    const F one = F{} + 1.0f;
    return r < -one ? -one : (r > one ? one : r);
}

// m lanes of noise of `kind`, W = sizeof(F) / 4 at a time.
template <class F, class I, class Corners>
MPSHADE_NOISE_INLINE void noiseLanesBody(const float* x, const float* y, const float* z,
                                         int octaves, NoiseSum kind, float* out, int m,
                                         const Corners& corners) {
    constexpr int W = static_cast<int>(sizeof(F) / sizeof(float));
    const int n = kind == NoiseSum::Single ? 1 : octaves;
    for (int first = 0; first < m; first += W) {
        const int count = std::min(W, m - first);
        // Whole vectors where W lanes remain: lanes written one by one into a vector go
        // through memory, a wider load then waiting on the stores.
        F px = {}, py = {}, pz = {};
        if (count == W) {
            std::memcpy(&px, x + first, sizeof px);
            std::memcpy(&py, y + first, sizeof py);
            std::memcpy(&pz, z + first, sizeof pz);
        } else {
            for (int l = 0; l < count; ++l)
                px[l] = x[first + l], py[l] = y[first + l], pz[l] = z[first + l];
        }
        F sum = {};
        float amp = 1.0f, freq = 1.0f;
        for (int i = 0; i < n; ++i) {
            const F fx = px * freq, fy = py * freq, fz = pz * freq;
            const I inside =
                inLatticeRange<F, I>(fx) & inLatticeRange<F, I>(fy) & inLatticeRange<F, I>(fz);
            const F zero = {};
            const F sx = inside != 0 ? fx : zero, sy = inside != 0 ? fy : zero,
                    sz = inside != 0 ? fz : zero;
            F value = snoiseLanes<F, I>(sx, sy, sz, corners);
            if (!corners.all(inside))
                for (int l = 0; l < count; ++l)
                    if (!inside[l]) value[l] = snoise3(fx[l], fy[l], fz[l]);
            if (kind == NoiseSum::Single) {
                sum = value;
                break;
            }
            if (kind == NoiseSum::Turbulence) value = (F)((I)value & 0x7fffffff);
            sum += amp * value;
            amp *= 0.5f;
            freq *= 2.0f;
        }
        if (count == W)
            std::memcpy(out + first, &sum, sizeof sum);
        else
            for (int l = 0; l < count; ++l) out[first + l] = sum[l];
    }
}

#undef MPSHADE_NOISE_INLINE

}  // namespace
}  // namespace mpshade
