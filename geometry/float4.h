// float4.h -- four floats as one vector register (GCC and Clang vector extensions: SSE on
// the x86-64 baseline, as wide as the build allows), for hot loops over RGBA or packed
// channels. Loads and stores go through memcpy: any alignment, no aliasing questions.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

#if defined(__SSE__)
#include <xmmintrin.h>
#endif

namespace mpshade {

using Float4 = float __attribute__((vector_size(16)));
// Four 32-bit integers: a Float4's comparison masks, and its lanes' bits.
using Int4 = int32_t __attribute__((vector_size(16)));

inline Float4 loadFloat4(const float* p) {
    Float4 v;
    std::memcpy(&v, p, sizeof v);
    return v;
}

inline void storeFloat4(float* p, Float4 v) {
    std::memcpy(p, &v, sizeof v);
}

inline Float4 splatFloat4(float x) {
    return Float4{x, x, x, x};
}

// Lane-wise square root, correctly rounded as std::sqrt is.
inline Float4 sqrtFloat4(Float4 v) {
#if defined(__SSE__)
    return reinterpret_cast<Float4>(_mm_sqrt_ps(reinterpret_cast<__m128>(v)));
#else
    return Float4{std::sqrt(v[0]), std::sqrt(v[1]), std::sqrt(v[2]), std::sqrt(v[3])};
#endif
}

}  // namespace mpshade
