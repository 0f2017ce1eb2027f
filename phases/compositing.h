// compositing.h -- what both renderers do with a shaded surface at a sample: the NaN
// policy, and front-to-back compositing over the background (Porter and Duff's "over",
// per channel).
#pragma once

#include <algorithm>
#include <cmath>

#include <glm/vec3.hpp>

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
