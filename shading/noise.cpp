#include "shading/noise.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "shading/noise_paths.h"

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

void noiseLanesPortable(const float* x, const float* y, const float* z, int octaves, NoiseSum kind,
                        float* out, int m) {
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

void noiseLanes(const float* x, const float* y, const float* z, int octaves, NoiseSum kind,
                float* out, int m) {
    static const NoisePath path = fastestNoisePath();
    noiseLanesOn(path, x, y, z, octaves, kind, out, m);
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

const uint8_t* noisePermutation() {
    return kPerm.p.data();
}

const float* noiseGradients(int axis) {
    return axis == 0 ? kGradients.x : (axis == 1 ? kGradients.y : kGradients.z);
}

bool noisePathAvailable(NoisePath path) {
    switch (path) {
        case NoisePath::Portable:
            return true;
        case NoisePath::Avx2:
            return __builtin_cpu_supports("avx2");
        case NoisePath::Avx512Vbmi:
            return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
                   __builtin_cpu_supports("avx512vbmi") && __builtin_cpu_supports("avx2");
    }
    return false;
}

NoisePath fastestNoisePath() {
    for (NoisePath path : {NoisePath::Avx512Vbmi, NoisePath::Avx2})
        if (noisePathAvailable(path)) return path;
    return NoisePath::Portable;
}

void noiseLanesOn(NoisePath path, const float* x, const float* y, const float* z, int octaves,
                  NoiseSum kind, float* out, int m) {
    switch (path) {
        case NoisePath::Avx512Vbmi:
            return noiseLanesAvx512Vbmi(x, y, z, octaves, kind, out, m);
        case NoisePath::Avx2:
            return noiseLanesAvx2(x, y, z, octaves, kind, out, m);
        case NoisePath::Portable:
            break;
    }
    noiseLanesPortable(x, y, z, octaves, kind, out, m);
}

}  // namespace mpshade
