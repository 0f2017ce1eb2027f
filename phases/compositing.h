// compositing.h -- what both renderers do with a shaded surface at a sample: the NaN
// policy, and front-to-back compositing over the background (Porter and Duff's "over",
// per channel).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

#include <glm/vec3.hpp>

#include "geometry/float4.h"

namespace mpshade {

// The NaN policy: a shader result with any non-finite component of Ci or Oi is counted
// and becomes opaque black, so one bad sample cannot poison a pixel. Opacity is clamped
// to [0, 1]. Returns false for a result that was not finite.
inline bool sanitizeShade(float ci[3], float oi[3]) {
    bool finite = true;
    for (int k = 0; k < 3; ++k) finite = finite && std::isfinite(ci[k]) && std::isfinite(oi[k]);
    if (!finite) {
        for (int k = 0; k < 3; ++k) ci[k] = 0.0f, oi[k] = 1.0f;
        return false;
    }
    for (int k = 0; k < 3; ++k) oi[k] = std::clamp(oi[k], 0.0f, 1.0f);
    return true;
}

// sanitizeShade over n results given as rows (ci[k][i], oi[k][i]), written interleaved
// (color[3 i + k], opacity[3 i + k]); returns how many were not finite. Four results at a
// time in vectors: x - x is 0 for a finite x and NaN otherwise, and a sum with a NaN is
// not 0; the scalar loop's per-result branches and stride-3 stores had cost more than the
// dynamic kernel of the vase (callgrind).
inline size_t sanitizeShadeRows(size_t n, const float* const ci[3], const float* const oi[3],
                                float* __restrict color, float* __restrict opacity) {
    size_t nonFinite = 0;
    size_t i = 0;
    const Float4 zero = splatFloat4(0.0f), one = splatFloat4(1.0f);
    // Lanes x0 x1 x2 x3 of rows a, b, c as a0 b0 c0 a1 | b1 c1 a2 b2 | c2 a3 b3 c3.
    auto interleave = [](Float4 a, Float4 b, Float4 c, float* out) {
        const Float4 ab = __builtin_shufflevector(a, b, 0, 4, 1, 5);
        const Float4 bc = __builtin_shufflevector(b, c, 1, 5, 2, 6);
        const Float4 ab3 = __builtin_shufflevector(a, b, 3, 7, 3, 7);
        storeFloat4(out, __builtin_shufflevector(ab, c, 0, 1, 4, 2));
        storeFloat4(out + 4, __builtin_shufflevector(bc, a, 0, 1, 6, 2));
        storeFloat4(out + 8, __builtin_shufflevector(c, ab3, 2, 4, 5, 3));
    };
    for (; i + 4 <= n; i += 4) {
        Float4 c[3], o[3];
        Float4 check = zero;
        for (int k = 0; k < 3; ++k) {
            c[k] = loadFloat4(ci[k] + i), o[k] = loadFloat4(oi[k] + i);
            check += (c[k] - c[k]) + (o[k] - o[k]);
        }
        const auto finite = check == zero;
#if defined(__SSE__)
        nonFinite += static_cast<size_t>(
            __builtin_popcount(~_mm_movemask_ps(reinterpret_cast<__m128>(finite)) & 0xF));
#else
        for (int k = 0; k < 4; ++k) nonFinite += finite[k] ? 0 : 1;
#endif
        for (int k = 0; k < 3; ++k) {
            c[k] = finite ? c[k] : zero;
            // std::clamp(o, 0, 1): o < 0 ? 0 : (1 < o ? 1 : o).
            o[k] = finite ? (o[k] < zero ? zero : (one < o[k] ? one : o[k])) : one;
        }
        interleave(c[0], c[1], c[2], color + 3 * i);
        interleave(o[0], o[1], o[2], opacity + 3 * i);
    }
    for (; i < n; ++i) {
        float c[3] = {ci[0][i], ci[1][i], ci[2][i]}, o[3] = {oi[0][i], oi[1][i], oi[2][i]};
        if (!sanitizeShade(c, o)) ++nonFinite;
        for (int k = 0; k < 3; ++k) color[3 * i + k] = c[k], opacity[3 * i + k] = o[k];
    }
    return nonFinite;
}

// Front-to-back accumulation for one sample: C += T Oi Ci, T *= 1 - Oi.
struct SampleComposite {
    float C[3] = {0.0f, 0.0f, 0.0f};
    float T[3] = {1.0f, 1.0f, 1.0f};

    void over(const float ci[3], const float oi[3]) {
        for (int k = 0; k < 3; ++k) {
            C[k] += T[k] * oi[k] * ci[k];
            T[k] *= 1.0f - oi[k];
        }
    }
    float transmittance() const { return std::max({T[0], T[1], T[2]}); }
    // RGBA over the background; alpha is the mean coverage 1 - T.
    void finish(const glm::vec3& background, float* rgba) const {
        for (int k = 0; k < 3; ++k) rgba[k] = C[k] + T[k] * background[k];
        rgba[3] = 1.0f - (T[0] + T[1] + T[2]) / 3.0f;
    }
};

}  // namespace mpshade
