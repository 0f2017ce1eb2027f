// float4.h -- four floats as one vector register (GCC and Clang vector extensions: SSE on
// the x86-64 baseline, as wide as the build allows), for hot loops over RGBA or packed
// channels. Loads and stores go through memcpy: any alignment, no aliasing questions.
#pragma once

#include <cstring>

namespace mpshade {

using Float4 = float __attribute__((vector_size(16)));

inline Float4 loadFloat4(const float* p) {
    Float4 v;
    std::memcpy(&v, p, sizeof v);
    return v;
}

inline void storeFloat4(float* p, Float4 v) {
    std::memcpy(p, &v, sizeof v);
}

}  // namespace mpshade
