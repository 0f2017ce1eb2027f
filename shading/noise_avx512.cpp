// The lane noise functions in AVX-512 registers, sixteen lanes at a time, with the
// permutation looked up in registers: the 256-entry table fits four 64-byte registers, and
// VBMI's vpermi2b looks a register of byte indices up in two of them at once (Ice Lake,
// Zen 4 and later). A lane's eight corner hashes take 14 lookups; by table each is a load
// whose index waits on the one before, here three instructions serve all sixteen lanes.
#include <immintrin.h>
#include <algorithm>
#include <cstdint>
#include <cstring>

#include "shading/noise.h"
#include "shading/noise_paths.h"

// Only the code below is built for AVX-512: the headers' inline functions above, which the
// linker may merge with other files' copies, stay baseline.
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx512f,avx512bw,avx512vbmi,avx2"))), \
                             apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx512f,avx512bw,avx512vbmi,avx2")
#endif

#include "shading/noise_lanes.h"

namespace mpshade {
namespace {

using Lanes16 = float __attribute__((vector_size(64)));
using Ints16 = int32_t __attribute__((vector_size(64)));

// The eight corners' hashes of sixteen cells, the table in four registers. Byte arithmetic
// wraps mod 256, which is all snoise3's indices need: its table repeats after 256 entries,
// so p[i] is p[i mod 256] for every index it forms (below 512).
struct CornersInRegisters {
    __m512i table[4];
    __m512 gradient[3];  // kGradients' columns, one lane per hash
    CornersInRegisters() {
        const uint8_t* p = noisePermutation();
        for (int q = 0; q < 4; ++q) table[q] = _mm512_loadu_si512(p + 64 * q);
        for (int axis = 0; axis < 3; ++axis) gradient[axis] = _mm512_loadu_ps(noiseGradients(axis));
    }
    // snoise3's grad: the table's row for the hash's low four bits (vpermps reads only them),
    // the same three products summed in the same order.
    [[gnu::always_inline]] Lanes16 grad(Ints16 h, Lanes16 x, Lanes16 y, Lanes16 z) const {
        const Lanes16 gx = (Lanes16)_mm512_maskz_permutexvar_ps(0xffff, (__m512i)h, gradient[0]);
        const Lanes16 gy = (Lanes16)_mm512_maskz_permutexvar_ps(0xffff, (__m512i)h, gradient[1]);
        const Lanes16 gz = (Lanes16)_mm512_maskz_permutexvar_ps(0xffff, (__m512i)h, gradient[2]);
        return gx * x + gy * y + gz * z;
    }
    [[gnu::always_inline]] static bool all(Ints16 mask) {
        return _mm512_cmpneq_epi32_mask((__m512i)mask, _mm512_setzero_si512()) == 0xffff;
    }
    // p[i] for each byte i: its low seven bits pick one of 128 entries in either half of
    // the table, its high bit the half.
    [[gnu::always_inline]] __m512i p(__m512i i) const {
        const __m512i low = _mm512_permutex2var_epi8(table[0], i, table[1]);
        const __m512i high = _mm512_permutex2var_epi8(table[2], i, table[3]);
        return _mm512_mask_blend_epi8(_mm512_movepi8_mask(i), low, high);
    }
    [[gnu::always_inline]] void operator()(Ints16 X, Ints16 Y, Ints16 Z, Ints16* h) const {
        const __m512i one = _mm512_set1_epi8(1);
        const __m512i x = bytes(X), y = bytes(Y), z = bytes(Z);
        const __m512i A = _mm512_add_epi8(p(x), y),
                      B = _mm512_add_epi8(p(_mm512_add_epi8(x, one)), y);
        const __m512i AA = _mm512_add_epi8(p(A), z),
                      AB = _mm512_add_epi8(p(_mm512_add_epi8(A, one)), z);
        const __m512i BA = _mm512_add_epi8(p(B), z),
                      BB = _mm512_add_epi8(p(_mm512_add_epi8(B, one)), z);
        const __m512i corner[8] = {AA,
                                   BA,
                                   AB,
                                   BB,
                                   _mm512_add_epi8(AA, one),
                                   _mm512_add_epi8(BA, one),
                                   _mm512_add_epi8(AB, one),
                                   _mm512_add_epi8(BB, one)};
        for (int k = 0; k < 8; ++k) h[k] = (Ints16)widen(p(corner[k]));
    }
    // The low sixteen bytes zero-extended to sixteen int32 lanes: byte k moved to byte 4k,
    // the bytes between zeroed (one vpermb).
    [[gnu::always_inline]] static __m512i widen(__m512i bytes) {
        const __m512i spread =
            _mm512_set_epi32(15, 14, 13, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0);
        return _mm512_maskz_permutexvar_epi8(0x1111111111111111ull, spread, bytes);
    }
    // Each cell's byte (0..255) in the low sixteen bytes, zeros above.
    [[gnu::always_inline]] static __m512i bytes(Ints16 cells) {
        return _mm512_zextsi128_si512(_mm512_maskz_cvtepi32_epi8(0xffff, (__m512i)cells));
    }
};

}  // namespace

void noiseLanesAvx512Vbmi(const float* x, const float* y, const float* z, int octaves,
                          NoiseSum kind, float* out, int m) {
    noiseLanesBody<Lanes16, Ints16>(x, y, z, octaves, kind, out, m, CornersInRegisters{});
}

}  // namespace mpshade

#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif
