// The lane noise functions in AVX2 registers, eight lanes at a time; the permutation is read
// one lane at a time (gathers had been slower than these byte loads).
#include <immintrin.h>
#include <algorithm>
#include <cstdint>
#include <cstring>

#include "shading/noise.h"
#include "shading/noise_paths.h"

// Only the code below is built for AVX2: the headers' inline functions above, which the
// linker may merge with other files' copies, stay baseline.
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2")
#endif

#include "shading/noise_lanes.h"

namespace mpshade {
namespace {

using Lanes8 = float __attribute__((vector_size(32)));
using Ints8 = int32_t __attribute__((vector_size(32)));

// The eight corners' hashes of eight cells by Perlin's table, as snoise3 indexes it.
struct CornersByTable {
    const uint8_t* p = noisePermutation();
    [[gnu::always_inline]] void operator()(Ints8 X, Ints8 Y, Ints8 Z, Ints8* h) const {
        for (int l = 0; l < 8; ++l) {
            const int A = p[X[l]] + Y[l], AA = p[A] + Z[l], AB = p[A + 1] + Z[l];
            const int B = p[X[l] + 1] + Y[l], BA = p[B] + Z[l], BB = p[B + 1] + Z[l];
            h[0][l] = p[AA], h[1][l] = p[BA], h[2][l] = p[AB], h[3][l] = p[BB];
            h[4][l] = p[AA + 1], h[5][l] = p[BA + 1], h[6][l] = p[AB + 1], h[7][l] = p[BB + 1];
        }
    }
    [[gnu::always_inline]] static Lanes8 grad(Ints8 h, Lanes8 x, Lanes8 y, Lanes8 z) {
        return gradLanes(h, x, y, z);
    }
    [[gnu::always_inline]] static bool all(Ints8 mask) {
        return _mm256_movemask_ps((__m256)mask) == 0xff;
    }
};

}  // namespace

void noiseLanesAvx2(const float* x, const float* y, const float* z, int octaves, NoiseSum kind,
                    float* out, int m) {
    noiseLanesBody<Lanes8, Ints8>(x, y, z, octaves, kind, out, m, CornersByTable{});
}

}  // namespace mpshade

#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif
