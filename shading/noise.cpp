#include "shading/noise.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace mpshade {
namespace {

// A fixed permutation of 0..255 (Fisher-Yates driven by a 32-bit LCG with a fixed seed):
// integer arithmetic only, so every machine builds the same table.
struct Permutation {
    std::array<uint8_t, 512> p{};
    Permutation() {
        std::array<uint8_t, 256> base{};
        for (int i = 0; i < 256; ++i) base[i] = static_cast<uint8_t>(i);
        uint32_t state = 0x6d707368u;  // "mpsh"
        for (int i = 255; i > 0; --i) {
            state = state * 1664525u + 1013904223u;
            const int j = static_cast<int>((state >> 8) % static_cast<uint32_t>(i + 1));
            std::swap(base[i], base[j]);
        }
        for (int i = 0; i < 512; ++i) p[i] = base[i & 255];
    }
};
const Permutation kPerm;

inline float fade(float t) {
    return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f);
}
inline float lerp(float t, float a, float b) {
    return a + t * (b - a);
}

// Perlin 2002's gradient: one of 12 cube-edge directions chosen by the hash (the low four
// bits; 12-15 repeat four of them), u +- v for the two coordinates the edge spans. As a
// table of the directions' components, so no branch depends on the hash: its branches,
// mispredicted half the time on random hashes, had taken most of a noise call.
struct Gradients {
    float x[16], y[16], z[16];
    constexpr Gradients() : x(), y(), z() {
        for (int h = 0; h < 16; ++h) {
            // Where the hash picks u and v, as Perlin's reference does.
            const int u = h < 8 ? 0 : 1;
            const int v = h < 4 ? 1 : (h == 12 || h == 14 ? 0 : 2);
            float* axis[3] = {x, y, z};
            axis[u][h] = (h & 1) ? -1.0f : 1.0f;
            axis[v][h] = (h & 2) ? -1.0f : 1.0f;
        }
    }
};
constexpr Gradients kGradients;

inline float grad(int hash, float x, float y, float z) {
    const int h = hash & 15;
    return kGradients.x[h] * x + kGradients.y[h] * y + kGradients.z[h] * z;
}

// Splits x into a lattice cell index (mod 256) and the fraction within the cell. False for
// non-finite input; huge inputs wrap without overflowing an int.
inline bool lattice(float x, int& cell, float& frac) {
    if (!std::isfinite(x)) return false;
    const double f = std::floor(static_cast<double>(x));
    frac = static_cast<float>(static_cast<double>(x) - f);
    if (std::fabs(f) < 0x1p62) {
        // An integer in int64's range: its residue mod 256 is its low byte (two's
        // complement makes that the non-negative residue for negative f too). fmod, a
        // library call, had taken most of a noise call's time.
        cell = static_cast<int>(static_cast<int64_t>(f) & 255);
        return true;
    }
    double m = std::fmod(f, 256.0);
    if (m < 0.0) m += 256.0;
    cell = static_cast<int>(m) & 255;
    return true;
}

inline uint32_t hash3(int64_t x, int64_t y, int64_t z) {
    // A 64-bit mix (splitmix64's finalizer) of the packed cell coordinates.
    uint64_t h = static_cast<uint64_t>(x) * 0x9E3779B97F4A7C15ull ^
                 static_cast<uint64_t>(y) * 0xC2B2AE3D27D4EB4Full ^
                 static_cast<uint64_t>(z) * 0x165667B19E3779F9ull;
    h ^= h >> 30;
    h *= 0xBF58476D1CE4E5B9ull;
    h ^= h >> 27;
    h *= 0x94D049BB133111EBull;
    h ^= h >> 31;
    return static_cast<uint32_t>(h);
}

inline int64_t cellOf(float x) {
    const double f = std::floor(static_cast<double>(x));
    return static_cast<int64_t>(std::fmax(std::fmin(f, 9.0e15), -9.0e15));
}

}  // namespace

float snoise3(float x, float y, float z) {
    int X, Y, Z;
    if (!lattice(x, X, x) || !lattice(y, Y, y) || !lattice(z, Z, z)) return 0.0f;
    const uint8_t* p = kPerm.p.data();
    const float u = fade(x), v = fade(y), w = fade(z);
    const int A = p[X] + Y, AA = p[A] + Z, AB = p[A + 1] + Z;
    const int B = p[X + 1] + Y, BA = p[B] + Z, BB = p[B + 1] + Z;
    const float r =
        lerp(w,
             lerp(v, lerp(u, grad(p[AA], x, y, z), grad(p[BA], x - 1, y, z)),
                  lerp(u, grad(p[AB], x, y - 1, z), grad(p[BB], x - 1, y - 1, z))),
             lerp(v, lerp(u, grad(p[AA + 1], x, y, z - 1), grad(p[BA + 1], x - 1, y, z - 1)),
                  lerp(u, grad(p[AB + 1], x, y - 1, z - 1), grad(p[BB + 1], x - 1, y - 1, z - 1))));
    // r is finite (the lattice rejects non-finite input), so a plain clamp: fmin and fmax
    // are library calls.
    return r < -1.0f ? -1.0f : (r > 1.0f ? 1.0f : r);
}

namespace {

// Eight lanes at a time in AVX2 registers (GCC vector extensions), each lane computing
// exactly what snoise3 computes for it, operation for operation, so the values are the
// same bit for bit. Lanes whose input is not finite or whose lattice cell does not fit an
// int32 are left to snoise3. Every function passing these vectors is compiled for AVX2
// (passing them without AVX changes the ABI, which Clang refuses); machines without AVX2
// take the one-point functions (four lanes in SSE registers had been no faster: the table
// lookups stay one lane at a time).
#define MPSHADE_AVX2 [[gnu::always_inline, gnu::target("avx2")]] inline
using Lanes8 = float __attribute__((vector_size(32)));
using Ints8 = int32_t __attribute__((vector_size(32)));
constexpr int kLanes = 8;

// floor(x) for |x| < 2^31 (exact: an integer-valued float) and its low byte.
MPSHADE_AVX2 void latticeLanes(Lanes8 x, Ints8& cell, Lanes8& frac) {
    const Ints8 t = __builtin_convertvector(x, Ints8);  // towards zero
    const Lanes8 tf = __builtin_convertvector(t, Lanes8);
    const Ints8 below = tf > x;  // -1 where truncation rounded up
    const Ints8 f = t + below;
    // x - floor(x) rounded once to float, as snoise3's exact double difference is.
    frac = x - __builtin_convertvector(f, Lanes8);
    cell = f & 255;
}

MPSHADE_AVX2 Lanes8 fadeLanes(Lanes8 t) {
    return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f);
}

MPSHADE_AVX2 Lanes8 lerpLanes(Lanes8 t, Lanes8 a, Lanes8 b) {
    return a + t * (b - a);
}

// kGradients' row for each lane's hash, as selects.
MPSHADE_AVX2 Lanes8 gradLanes(Ints8 hash, Lanes8 x, Lanes8 y, Lanes8 z) {
    const Ints8 h = hash & 15;
    const Lanes8 one = {1, 1, 1, 1, 1, 1, 1, 1}, zero = {};
    const Lanes8 su = (h & 1) != 0 ? -one : one, sv = (h & 2) != 0 ? -one : one;
    const Ints8 vx = (h == 12) | (h == 14);
    const Lanes8 gx = (h < 8 ? su : zero) + (vx != 0 ? sv : zero);
    const Lanes8 gy = (h >= 8 ? su : zero) + (h < 4 ? sv : zero);
    const Lanes8 gz = ((h >= 4) & ~vx) != 0 ? sv : zero;
    return gx * x + gy * y + gz * z;
}

MPSHADE_AVX2 Lanes8 snoiseLanes(Lanes8 x, Lanes8 y, Lanes8 z) {
    Ints8 X, Y, Z;
    latticeLanes(x, X, x);
    latticeLanes(y, Y, y);
    latticeLanes(z, Z, z);
    const uint8_t* p = kPerm.p.data();
    // The eight corners' hashes, one lane at a time (table lookups).
    Ints8 h[8];
    for (int l = 0; l < kLanes; ++l) {
        const int A = p[X[l]] + Y[l], AA = p[A] + Z[l], AB = p[A + 1] + Z[l];
        const int B = p[X[l] + 1] + Y[l], BA = p[B] + Z[l], BB = p[B + 1] + Z[l];
        h[0][l] = p[AA], h[1][l] = p[BA], h[2][l] = p[AB], h[3][l] = p[BB];
        h[4][l] = p[AA + 1], h[5][l] = p[BA + 1], h[6][l] = p[AB + 1], h[7][l] = p[BB + 1];
    }
    const Lanes8 u = fadeLanes(x), v = fadeLanes(y), w = fadeLanes(z);
    const Lanes8 x1 = x - 1.0f, y1 = y - 1.0f, z1 = z - 1.0f;
    const Lanes8 r =
        lerpLanes(w,
                  lerpLanes(v, lerpLanes(u, gradLanes(h[0], x, y, z), gradLanes(h[1], x1, y, z)),
                            lerpLanes(u, gradLanes(h[2], x, y1, z), gradLanes(h[3], x1, y1, z))),
                  lerpLanes(v, lerpLanes(u, gradLanes(h[4], x, y, z1), gradLanes(h[5], x1, y, z1)),
                            lerpLanes(u, gradLanes(h[6], x, y1, z1), gradLanes(h[7], x1, y1, z1))));
    const Lanes8 one = {1, 1, 1, 1, 1, 1, 1, 1};
    return r < -one ? -one : (r > one ? one : r);
}

// |x| < 2^30, so floor(x) fits an int32 (false for NaN and infinities): the lanes
// snoiseLanes computes as snoise3 does.
MPSHADE_AVX2 Ints8 inLatticeRange(Lanes8 x) {
    const Ints8 magnitude = (Ints8)x & 0x7fffffff;
    const Lanes8 limit = {0x1p30f, 0x1p30f, 0x1p30f, 0x1p30f, 0x1p30f, 0x1p30f, 0x1p30f, 0x1p30f};
    return (Lanes8)magnitude < limit;
}

enum class NoiseSum { Single, Fbm, Turbulence };

__attribute__((target("avx2"))) void noiseLanesAvx2(const float* x, const float* y, const float* z,
                                                    int octaves, NoiseSum kind, float* out, int m) {
    const int n = kind == NoiseSum::Single ? 1 : octaves;
    for (int first = 0; first < m; first += kLanes) {
        const int count = std::min(kLanes, m - first);
        // Whole vectors where eight lanes remain: lanes written one by one into a vector go
        // through memory, a wider load then waiting on the stores.
        Lanes8 px = {}, py = {}, pz = {};
        if (count == kLanes) {
            std::memcpy(&px, x + first, sizeof px);
            std::memcpy(&py, y + first, sizeof py);
            std::memcpy(&pz, z + first, sizeof pz);
        } else {
            for (int l = 0; l < count; ++l)
                px[l] = x[first + l], py[l] = y[first + l], pz[l] = z[first + l];
        }
        Lanes8 sum = {};
        float amp = 1.0f, freq = 1.0f;
        for (int i = 0; i < n; ++i) {
            Lanes8 fx = px * freq, fy = py * freq, fz = pz * freq;
            const Ints8 inside = inLatticeRange(fx) & inLatticeRange(fy) & inLatticeRange(fz);
            const Lanes8 zero = {};
            const Lanes8 sx = inside != 0 ? fx : zero, sy = inside != 0 ? fy : zero,
                         sz = inside != 0 ? fz : zero;
            Lanes8 value = snoiseLanes(sx, sy, sz);
            for (int l = 0; l < count; ++l)
                if (!inside[l]) value[l] = snoise3(fx[l], fy[l], fz[l]);
            if (kind == NoiseSum::Single) {
                sum = value;
                break;
            }
            if (kind == NoiseSum::Turbulence) {
                const Ints8 bits = (Ints8)value & 0x7fffffff;
                value = (Lanes8)bits;
            }
            sum += amp * value;
            amp *= 0.5f;
            freq *= 2.0f;
        }
        if (count == kLanes)
            std::memcpy(out + first, &sum, sizeof sum);
        else
            for (int l = 0; l < count; ++l) out[first + l] = sum[l];
    }
}

#undef MPSHADE_AVX2

void noiseLanes(const float* x, const float* y, const float* z, int octaves, NoiseSum kind,
                float* out, int m) {
    static const bool avx2 = __builtin_cpu_supports("avx2");
    if (avx2) return noiseLanesAvx2(x, y, z, octaves, kind, out, m);
    for (int l = 0; l < m; ++l) {
        switch (kind) {
            case NoiseSum::Single:
                out[l] = snoise3(x[l], y[l], z[l]);
                break;
            case NoiseSum::Fbm:
                out[l] = fbm3(x[l], y[l], z[l], octaves);
                break;
            case NoiseSum::Turbulence:
                out[l] = turbulence3(x[l], y[l], z[l], octaves);
                break;
        }
    }
}

}  // namespace

void snoise3Lanes(const float* x, const float* y, const float* z, float* out, int m) {
    noiseLanes(x, y, z, 1, NoiseSum::Single, out, m);
}

void fbm3Lanes(const float* x, const float* y, const float* z, int octaves, float* out, int m) {
    noiseLanes(x, y, z, octaves, NoiseSum::Fbm, out, m);
}

void turbulence3Lanes(const float* x, const float* y, const float* z, int octaves, float* out,
                      int m) {
    noiseLanes(x, y, z, octaves, NoiseSum::Turbulence, out, m);
}

float noise3(float x, float y, float z) {
    return 0.5f + 0.5f * snoise3(x, y, z);
}

void noise3Lanes(const float* x, const float* y, const float* z, float* out, int m) {
    snoise3Lanes(x, y, z, out, m);
    for (int l = 0; l < m; ++l) out[l] = 0.5f + 0.5f * out[l];
}

float cellnoise3(float x, float y, float z) {
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) return 0.0f;
    return static_cast<float>(hash3(cellOf(x), cellOf(y), cellOf(z)) >> 8) * (1.0f / 16777216.0f);
}

float fbm3(float x, float y, float z, int octaves) {
    float sum = 0.0f, amp = 1.0f, freq = 1.0f;
    for (int i = 0; i < octaves; ++i) {
        sum += amp * snoise3(x * freq, y * freq, z * freq);
        amp *= 0.5f;
        freq *= 2.0f;
    }
    return sum;
}

float turbulence3(float x, float y, float z, int octaves) {
    float sum = 0.0f, amp = 1.0f, freq = 1.0f;
    for (int i = 0; i < octaves; ++i) {
        sum += amp * std::fabs(snoise3(x * freq, y * freq, z * freq));
        amp *= 0.5f;
        freq *= 2.0f;
    }
    return sum;
}

}  // namespace mpshade
