// lighting.h -- the lighting and visibility builtins on a run of lanes (spec: "Lighting").
//
// For one light: L is the unit direction to the light and Cl its color arriving at P
// (point lights fall off as 1 / distance^2).
//   diffuse:  Cl max(0, N.L)
//   specular: Cl D(N.H) max(0, N.L) / 4, H = normalize(L + V), D the GGX (Trowbridge-Reitz)
//             distribution alpha^2 / (pi ((N.H)^2 (alpha^2 - 1) + 1)^2) with
//             alpha = roughness^2 (roughness clamped to [0.01, 1])
//   phong:    Cl max(0, R.L)^exponent, R = reflect(-V, N)
// occlusion: the cosine-weighted fraction of the hemisphere around N left open by the
// object's own geometry, from `rays` directions of a fixed Hammersley pattern, so it is a
// deterministic function of P and N.
#pragma once

#include <cstdint>

#include "shading/interpreter.h"
#include "shading/stop_signal.h"

namespace mpshade {

// args: P(3) N(3) [V(3) param]; each a run of m lanes. Writes rgb[3][m]: the light, or what
// `epilogue` (may be null) makes of it. negatedView (Specular only): args 6-8 hold -V, as a
// shader's specular(N, -I, r) has them before I is negated; the same bits as negating them
// first (but for a NaN's sign). rgb may not alias args or the epilogue's rows.
void shadeLight(Op op, const LightSample& light, const float* const* args, float* const* rgb, int m,
                bool negatedView = false, const LightEpilogue* epilogue = nullptr);

// shadeLight in baseline code (four lanes at a time and one) whatever the processor, for
// tests of the AVX2 path against it.
void shadeLightBaseline(Op op, const LightSample& light, const float* const* args,
                        float* const* rgb, int m, bool negatedView = false,
                        const LightEpilogue* epilogue = nullptr);

// args: P(3) N(3). Writes the open fraction per lane; returns the rays traced. `stop` (may
// be null) is checked before each stream of rays (64 lanes' ray i): once it says stop, the
// rest are not traced and `out` is left unspecified -- for a caller that then drops the
// results (a shader-map fill stopped at its deadline, within tens of microseconds rather
// than a kernel run of occlusion, a millisecond for 128 texels of 8 rays).
uint64_t occlusionLanes(const SurfaceRayScene* occluder, float bias, int rays,
                        const float* const* args, float* out, int m,
                        const StopSignal* stop = nullptr);

// One lane of each, for tests and the constant folder's peers.
glm::vec3 shadeLightOne(Op op, const LightSample& light, const glm::vec3& P, const glm::vec3& N,
                        const glm::vec3& V, float param);

}  // namespace mpshade
