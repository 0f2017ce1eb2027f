// noise.h -- deterministic procedural noise (the same values on every machine and run).
//
// snoise3: Perlin's improved gradient noise (Perlin 2002, "Improving Noise") with his
// reference permutation and 12 edge gradients; zero at integer lattice points, clamped
// to [-1, 1]. noise3 = 0.5 + 0.5 snoise3, in [0, 1]. cellnoise3: a hash of the unit cell
// containing p, in [0, 1), constant per cell. fbm3: sum over octaves i < n of
// 0.5^i snoise3(2^i p); turbulence3: the same sum of |snoise3|.
#pragma once

namespace mpshade {

float snoise3(float x, float y, float z);
float noise3(float x, float y, float z);
float cellnoise3(float x, float y, float z);
float fbm3(float x, float y, float z, int octaves);
float turbulence3(float x, float y, float z, int octaves);

// The same over m lanes (rows of coordinates; out a row of m, not one of them): each lane's
// value is the one-point function's, bit for bit, by the fastest build the processor runs
// (noise_paths.h): sixteen lanes in AVX-512 registers with the permutation looked up in
// them (VBMI; about 6x the one-point functions' speed), eight in AVX2 registers (about 2x),
// or one at a time.
void snoise3Lanes(const float* x, const float* y, const float* z, float* out, int m);
void noise3Lanes(const float* x, const float* y, const float* z, float* out, int m);
void fbm3Lanes(const float* x, const float* y, const float* z, int octaves, float* out, int m);
void turbulence3Lanes(const float* x, const float* y, const float* z, int octaves, float* out,
                      int m);

}  // namespace mpshade
