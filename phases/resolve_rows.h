// resolve_rows.h -- a band of SampleLayout::resolve (sample_pattern.h): the per-sample
// colors of the rows in the filter's reach added, weighted, to the band's pixels. Included
// by sample_pattern.cpp (the baseline build), resolve_avx512.cpp and resolve_avx2.cpp
// (built for AVX-512 and AVX2 and chosen at run time); internal linkage, so each file has its
// own copy for its own instruction set. The files build with contraction off, and the wider
// builds' sum of a pixel's samples does per lane the very multiplications and additions of
// the baseline's, in the same order: every build gives the same bits.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "geometry/float4.h"
#include "phases/resolve_frame.h"

#if defined(MPSHADE_RESOLVE_AVX512) || defined(MPSHADE_RESOLVE_AVX2)
#include <immintrin.h>
#endif

namespace mpshade {

// NOLINTNEXTLINE(cert-dcl59-cpp,google-build-namespaces): one copy per instruction set
namespace {

// The resolve's writes: out-pixel rows [py0, py1] of the `pixels` image (width wide, RGBA),
// each getting weights (its row of `w`, `stride` apart and offset by the first row's
// distance `row0` from the source) times a color, over `columns` pixels from column x.
template <int columns>
[[gnu::always_inline]] inline void addWeighted(float* pixels, int width, int x, int py0, int py1,
                                               int row0, const float* w, int stride,
                                               const Float4& c) {
    for (int py = py0; py <= py1; ++py) {
        const float* wr = w + stride * (py - row0);
        float* o = pixels + (static_cast<size_t>(py) * width + x) * 4;
        for (int k = 0; k < columns; ++k) storeFloat4(o + 4 * k, loadFloat4(o + 4 * k) + wr[k] * c);
    }
}

// A pixel's samples [first, last) with a filter reaching one pixel around, summed in
// registers first, so each pixel in reach is read and written once per pixel rather than
// once per sample. Sample s adds w[3 + r] (w[k] c) to the pixel k - 1 columns and r - 1 rows
// away, w = its six weights.
[[gnu::always_inline]] inline void addSamples3x3(float* pixels, int width, int qx, int qy, int py0,
                                                 int py1, const float* rgba, const float* weights,
                                                 size_t first, size_t last) {
#if defined(MPSHADE_RESOLVE_AVX512)
    // The three columns' products side by side in one register, (w0 c | w1 c | w2 c | 0):
    // four multiplications and three additions a sample against the baseline's twelve and
    // nine, the same products in each lane.
    const __m512i column = _mm512_setr_epi32(0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3);
    __m512 sum[3] = {_mm512_setzero_ps(), _mm512_setzero_ps(), _mm512_setzero_ps()};
    for (size_t s = first; s < last; ++s) {
        const float* w = weights + s * 6;
        const __m512 color = _mm512_maskz_broadcast_f32x4(0xFFFF, _mm_loadu_ps(rgba + 4 * s));
        const __m512 wx =
            _mm512_maskz_permutexvar_ps(0x0FFF, column, _mm512_zextps128_ps512(_mm_loadu_ps(w)));
        const __m512 cw = _mm512_mul_ps(wx, color);
        for (int r = 0; r < 3; ++r)
            sum[r] = _mm512_add_ps(sum[r], _mm512_mul_ps(_mm512_set1_ps(w[3 + r]), cw));
    }
    for (int r = 0; r < 3; ++r) {
        const int py = qy - 1 + r;
        if (py < py0 || py > py1) continue;
        float* o = pixels + (static_cast<size_t>(py) * width + qx - 1) * 4;
        _mm_storeu_ps(o, _mm_add_ps(_mm_loadu_ps(o), _mm512_maskz_extractf32x4_ps(0xF, sum[r], 0)));
        _mm_storeu_ps(
            o + 4, _mm_add_ps(_mm_loadu_ps(o + 4), _mm512_maskz_extractf32x4_ps(0xF, sum[r], 1)));
        _mm_storeu_ps(
            o + 8, _mm_add_ps(_mm_loadu_ps(o + 8), _mm512_maskz_extractf32x4_ps(0xF, sum[r], 2)));
    }
#elif defined(MPSHADE_RESOLVE_AVX2)
    // Two columns' products side by side, (w0 c | w1 c), and the third alone: ten
    // multiplications and additions a sample against the baseline's twenty-one, the same
    // products in each lane.
    const __m256i pair = _mm256_setr_epi32(0, 0, 0, 0, 1, 1, 1, 1);
    __m256 sum01[3] = {_mm256_setzero_ps(), _mm256_setzero_ps(), _mm256_setzero_ps()};
    __m128 sum2[3] = {_mm_setzero_ps(), _mm_setzero_ps(), _mm_setzero_ps()};
    for (size_t s = first; s < last; ++s) {
        const float* w = weights + s * 6;
        const __m128 c = _mm_loadu_ps(rgba + 4 * s);
        const __m256 w01 = _mm256_permutevar8x32_ps(_mm256_castps128_ps256(_mm_loadu_ps(w)), pair);
        const __m256 cw01 = _mm256_mul_ps(w01, _mm256_set_m128(c, c));
        const __m128 cw2 = _mm_mul_ps(_mm_set1_ps(w[2]), c);
        for (int r = 0; r < 3; ++r) {
            sum01[r] = _mm256_add_ps(sum01[r], _mm256_mul_ps(_mm256_set1_ps(w[3 + r]), cw01));
            sum2[r] = _mm_add_ps(sum2[r], _mm_mul_ps(_mm_set1_ps(w[3 + r]), cw2));
        }
    }
    for (int r = 0; r < 3; ++r) {
        const int py = qy - 1 + r;
        if (py < py0 || py > py1) continue;
        float* o = pixels + (static_cast<size_t>(py) * width + qx - 1) * 4;
        _mm_storeu_ps(o, _mm_add_ps(_mm_loadu_ps(o), _mm256_castps256_ps128(sum01[r])));
        _mm_storeu_ps(o + 4, _mm_add_ps(_mm_loadu_ps(o + 4), _mm256_extractf128_ps(sum01[r], 1)));
        _mm_storeu_ps(o + 8, _mm_add_ps(_mm_loadu_ps(o + 8), sum2[r]));
    }
#else
    Float4 sum[3][3];
    for (auto& row : sum)
        for (Float4& v : row) v = splatFloat4(0.0f);
    for (size_t s = first; s < last; ++s) {
        const float* w = weights + s * 6;
        const Float4 c = loadFloat4(rgba + 4 * s);
        const Float4 c0 = w[0] * c, c1 = w[1] * c, c2 = w[2] * c;
        for (int r = 0; r < 3; ++r) {
            sum[r][0] += w[3 + r] * c0;
            sum[r][1] += w[3 + r] * c1;
            sum[r][2] += w[3 + r] * c2;
        }
    }
    for (int py = py0; py <= py1; ++py) {
        const Float4* add = sum[py - qy + 1];
        float* o = pixels + (static_cast<size_t>(py) * width + qx - 1) * 4;
        storeFloat4(o, loadFloat4(o) + add[0]);
        storeFloat4(o + 4, loadFloat4(o + 4) + add[1]);
        storeFloat4(o + 8, loadFloat4(o + 8) + add[2]);
    }
#endif
}

// Whether the 2x2 block (bx, by) holds four uniform pixels of one color, bit for bit, as
// the dynamic phase marks alike pixels.
inline bool blockAlike(const ResolveFrame& f, int bx, int by) {
    const size_t w = static_cast<size_t>(f.width);
    const size_t p = static_cast<size_t>(2 * by) * w + 2 * static_cast<size_t>(bx);
    if (!(f.uniform[p] && f.uniform[p + 1] && f.uniform[p + w] && f.uniform[p + w + 1]))
        return false;
    uint64_t first[2];
    std::memcpy(first, f.rgba + 4 * p * f.spp, 16);
    auto same = [&](size_t q) {
        uint64_t other[2];
        std::memcpy(other, f.rgba + 4 * q * f.spp, 16);
        return ((first[0] ^ other[0]) | (first[1] ^ other[1])) == 0;
    };
    return same(p + 1) && same(p + w) && same(p + w + 1);
}

// Output rows [r0, r1) of the frame's output: every sample of the rows in reach (and of its
// columns) read once and added to the pixels it reaches in the band (SampleLayout::resolve
// says how), then each pixel of the output's rows normalized. The writes go to the output's
// window: image pixel (px, py) at its (px - x0, py - y0), rows `stride` pixels apart (the
// whole image: 0, 0, width).
inline void resolveRowsOf(const ResolveFrame& f, int r0, int r1) {
    const int width = f.width, height = f.height, reach = f.reach;
    const size_t taps = f.taps, spp = f.spp;
    const float* rgba = f.rgba;
    float* pixels = f.pixels;
    const int stride = f.stride, dx = f.x0, dy = f.y0;
    const int blocksX = width / 2;
    std::fill(pixels + static_cast<size_t>(r0 - dy) * stride * 4,
              pixels + static_cast<size_t>(r1 - dy) * stride * 4, 0.0f);
    // With blocks, from an even row, so every 2x2 block in reach is met at its top row.
    const int firstRow = std::max(0, r0 - reach) & (f.blocks ? ~1 : ~0);
    for (int qy = firstRow; qy < std::min(height, r1 + reach); ++qy) {
        const int py0 = std::max(r0, qy - reach), py1 = std::min(r1 - 1, qy + reach);
        const int by = qy / 2;
        const bool blockRow = f.blocks && by >= 1 && 2 * by + 2 < height;
        bool alike = false;  // the current block's, found at its left column
        for (int qx = f.col0; qx < f.col1; ++qx) {
            if (qx % 2 == 0)
                alike = blockRow && qx >= 2 && qx + 3 < width && blockAlike(f, qx / 2, by);
            if (alike) {
                // A 2x2 block shaded once (at one shading point per 2x2 pixels): its one
                // color to the 4 x 4 pixels it reaches, from its top row, for both.
                if (qy % 2 == 0 && qx % 2 == 0)
                    addWeighted<4>(
                        pixels, stride, qx - 1 - dx, std::max(r0, qy - 1) - dy,
                        std::min(r1 - 1, qy + 2) - dy, qy - 1 - dy,
                        f.blockWeights + (static_cast<size_t>(by) * blocksX + qx / 2) * 16, 4,
                        loadFloat4(rgba + 4 * (static_cast<size_t>(qy) * width + qx) * spp));
                continue;
            }
            if (py0 > py1) continue;  // a row read for the blocks it starts
            const size_t pixel = static_cast<size_t>(qy) * width + qx;
            const size_t first = pixel * spp;
            const bool same = f.uniform && f.uniform[pixel];
            const size_t last = same ? first + 1 : first + spp;
            if (reach == 1 && qx > 0 && qx + 1 < width) {
                if (same)  // one color, its samples' weights summed
                    addWeighted<3>(pixels, stride, qx - 1 - dx, py0 - dy, py1 - dy, qy - 1 - dy,
                                   f.pixelWeights + pixel * 9, 3, loadFloat4(rgba + 4 * first));
                else
                    addSamples3x3(pixels, stride, qx - dx, qy - dy, py0 - dy, py1 - dy, rgba,
                                  f.weights, first, last);
                continue;
            }
            // The general case: a wider filter, or a pixel at the image's edge.
            const int px0 = std::max(0, qx - reach), px1 = std::min(width - 1, qx + reach);
            for (size_t s = first; s < last; ++s) {
                const float* w =
                    same ? f.pixelWeights + pixel * taps * taps : f.weights + s * 2 * taps;
                const Float4 c = loadFloat4(rgba + 4 * s);
                for (int py = py0; py <= py1; ++py) {
                    const size_t oy = static_cast<size_t>(py - qy + reach);
                    float* row = pixels + static_cast<size_t>(py - dy) * stride * 4;
                    for (int px = px0; px <= px1; ++px) {
                        const size_t ox = static_cast<size_t>(px - qx + reach);
                        const float k = same ? w[oy * taps + ox] : w[taps + oy] * w[ox];
                        float* o = row + 4 * static_cast<size_t>(px - dx);
                        storeFloat4(o, loadFloat4(o) + k * c);
                    }
                }
            }
        }
    }
    for (int py = r0; py < r1; ++py) {
        float* o = pixels + static_cast<size_t>(py - dy) * stride * 4;
        const float* inverse = f.inverseSum + static_cast<size_t>(py) * width + dx;
        for (int k = 0; k < stride; ++k) storeFloat4(o + 4 * k, loadFloat4(o + 4 * k) * inverse[k]);
    }
}

}  // namespace
}  // namespace mpshade
