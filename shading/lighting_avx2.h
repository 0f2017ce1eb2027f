// lighting_avx2.h -- diffuse and specular light eight lanes at a time in AVX2 registers,
// chosen at run time by shadeLight (lighting.h); bit for bit the baseline's values (the
// same operations in the same order, light_lanes.h; no fused multiply-add).
#pragma once

#include "shading/interpreter.h"

namespace mpshade {

// True where this build has the AVX2 path and the processor runs it.
bool shadeLightAvx2Available();
// shadeLight for Diffuse and Specular (not Phong). Only where shadeLightAvx2Available().
void shadeLightAvx2(Op op, const LightSample& light, const float* const* args, float* const* rgb,
                    int m, bool negatedView = false, const LightEpilogue* epilogue = nullptr);

}  // namespace mpshade
