// noise_paths.h -- the builds of the lane noise functions (noise.h), one per instruction
// set, for noise.cpp to choose from at run time and for tests and benchmarks to run each.
// Every path gives each lane the one-point function's value bit for bit.
#pragma once

#include <cstdint>

namespace mpshade {

enum class NoiseSum { Single, Fbm, Turbulence };

enum class NoisePath {
    Portable,    // one point at a time (snoise3, fbm3, turbulence3)
    Avx2,        // eight lanes in AVX2 registers, the permutation read one lane at a time
    Avx512Vbmi,  // sixteen lanes in AVX-512 registers, the permutation looked up in registers
};

// True where this build has the path and the processor runs it (Portable always).
bool noisePathAvailable(NoisePath path);
// The fastest available path: what snoise3Lanes and the others run.
NoisePath fastestNoisePath();

// m lanes of noise of `kind` (Single ignores octaves) by `path`, which must be available.
void noiseLanesOn(NoisePath path, const float* x, const float* y, const float* z, int octaves,
                  NoiseSum kind, float* out, int m);

// Perlin's permutation as noise.cpp builds it: 512 entries, the second 256 repeating the first.
const uint8_t* noisePermutation();
// Perlin's 12 edge gradients as snoise3 reads them: component `axis` (0-2) of the gradient of
// each hash's low four bits, 16 entries.
const float* noiseGradients(int axis);

// The vector builds (noise_avx2.cpp, noise_avx512.cpp): only where noisePathAvailable.
void noiseLanesAvx2(const float* x, const float* y, const float* z, int octaves, NoiseSum kind,
                    float* out, int m);
void noiseLanesAvx512Vbmi(const float* x, const float* y, const float* z, int octaves,
                          NoiseSum kind, float* out, int m);

}  // namespace mpshade
