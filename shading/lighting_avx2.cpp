#include "shading/lighting_avx2.h"

#if defined(__x86_64__) || defined(__i386__)

// Every header the lanes use comes in before the target switch, so only the code below is
// built for AVX2: inline functions of those headers, which the linker may merge with other
// files' copies, stay baseline.
#include <immintrin.h>
#include <cmath>
#include <cstring>
#include <type_traits>

#include "geometry/float4.h"
#include "shading/scalar_ops.h"

#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2")
#endif

namespace mpshade {
namespace {

using Lanes8 = float __attribute__((vector_size(32)));

// The lane operations of light_lanes.h for eight lanes, declared before it so its
// formulas find them.
inline Lanes8 splat(float x, Lanes8) {
    return Lanes8{x, x, x, x, x, x, x, x};
}
inline Lanes8 load(const float* p, Lanes8) {
    Lanes8 v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
inline void store(float* p, Lanes8 v) {
    std::memcpy(p, &v, sizeof v);
}
// Correctly rounded, as std::sqrt is.
inline Lanes8 root(Lanes8 x) {
    return reinterpret_cast<Lanes8>(_mm256_sqrt_ps(reinterpret_cast<__m256>(x)));
}

}  // namespace
}  // namespace mpshade

#include "shading/light_lanes.h"

namespace mpshade {
namespace {

template <Op kOp, bool kPoint, bool kNegV, bool kEpi>
void lanes(const LightSample& light, const float* const* args, float* const* rgb, int m,
           const LightEpilogue* epilogue) {
    int l = 0;
    for (; l + 8 <= m; l += 8)
        shadeLightLanes<kOp, kPoint, Lanes8, kNegV, kEpi>(light, args, rgb, l, epilogue);
    for (; l + 4 <= m; l += 4)
        shadeLightLanes<kOp, kPoint, Float4, kNegV, kEpi>(light, args, rgb, l, epilogue);
    for (; l < m; ++l)
        shadeLightLanes<kOp, kPoint, float, kNegV, kEpi>(light, args, rgb, l, epilogue);
}

template <Op kOp, bool kNegV, bool kEpi>
void lanes(const LightSample& light, const float* const* args, float* const* rgb, int m,
           const LightEpilogue* epilogue) {
    if (light.kind == LightKind::Point)
        lanes<kOp, true, kNegV, kEpi>(light, args, rgb, m, epilogue);
    else
        lanes<kOp, false, kNegV, kEpi>(light, args, rgb, m, epilogue);
}

template <Op kOp, bool kNegV>
void lanes(const LightSample& light, const float* const* args, float* const* rgb, int m,
           const LightEpilogue* epilogue) {
    if (epilogue)
        lanes<kOp, kNegV, true>(light, args, rgb, m, epilogue);
    else
        lanes<kOp, kNegV, false>(light, args, rgb, m, epilogue);
}

}  // namespace

void shadeLightAvx2(Op op, const LightSample& light, const float* const* args, float* const* rgb,
                    int m, bool negatedView, const LightEpilogue* epilogue) {
    if (op == Op::Diffuse)
        lanes<Op::Diffuse, false>(light, args, rgb, m, epilogue);
    else if (negatedView)
        lanes<Op::Specular, true>(light, args, rgb, m, epilogue);
    else
        lanes<Op::Specular, false>(light, args, rgb, m, epilogue);
}

}  // namespace mpshade

#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif

namespace mpshade {

bool shadeLightAvx2Available() {
    static const bool available = __builtin_cpu_supports("avx2");
    return available;
}

}  // namespace mpshade

#else  // not x86: the baseline path only

namespace mpshade {

bool shadeLightAvx2Available() {
    return false;
}
void shadeLightAvx2(Op, const LightSample&, const float* const*, float* const*, int, bool,
                    const LightEpilogue*) {}

}  // namespace mpshade

#endif
