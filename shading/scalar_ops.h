// scalar_ops.h -- the meaning of each pure IR operation on one lane. The constant folder and
// the batched interpreter both use these, so folding can never change a result.
//
// NaN policy (as OSL's "safe" math): x / 0 = 0, sqrt(x < 0) = 0, log(x <= 0) =
// log(FLT_MIN), pow(0, y) = 0, pow(x < 0, non-integer y) = 0, asin/acos clamp to [-1, 1],
// mod(x, 0) = 0. So no builtin makes a NaN from finite inputs; Inf arithmetic still can,
// and the renderers count and zero non-finite samples.
#pragma once

#include <algorithm>
#include <cfloat>
#include <cmath>

#include "shading/ir.h"
#include "shading/noise.h"

namespace mpshade::scalar {

inline float safeDiv(float a, float b) {
    return b == 0.0f ? 0.0f : a / b;
}
inline float safeSqrt(float x) {
    return x > 0.0f ? std::sqrt(x) : 0.0f;
}
inline float safeLog(float x) {
    return std::log(std::max(x, FLT_MIN));
}
inline float safePow(float x, float y) {
    if (x == 0.0f) return 0.0f;
    if (x < 0.0f && y != std::floor(y)) return 0.0f;
    return std::pow(x, y);
}
inline float clamp01(float x) {
    return std::min(std::max(x, 0.0f), 1.0f);
}
inline float mod(float a, float b) {
    return b == 0.0f ? 0.0f : a - b * std::floor(a / b);
}
inline float smoothstep(float e0, float e1, float x) {
    if (e0 == e1) return x < e0 ? 0.0f : 1.0f;
    const float t = clamp01((x - e0) / (e1 - e0));
    return t * t * (3.0f - 2.0f * t);
}
inline float sign(float x) {
    return x > 0.0f ? 1.0f : (x < 0.0f ? -1.0f : 0.0f);
}
inline float truthy(float x) {
    return x != 0.0f ? 1.0f : 0.0f;
}

inline float unary(Op op, float a) {
    switch (op) {
        case Op::Neg:
            return -a;
        case Op::Abs:
            return std::fabs(a);
        case Op::Floor:
            return std::floor(a);
        case Op::Ceil:
            return std::ceil(a);
        case Op::Fract:
            return a - std::floor(a);
        case Op::Sqrt:
            return safeSqrt(a);
        case Op::Exp:
            return std::exp(a);
        case Op::Log:
            return safeLog(a);
        case Op::Sin:
            return std::sin(a);
        case Op::Cos:
            return std::cos(a);
        case Op::Tan:
            return std::tan(a);
        case Op::Asin:
            return std::asin(std::clamp(a, -1.0f, 1.0f));
        case Op::Acos:
            return std::acos(std::clamp(a, -1.0f, 1.0f));
        case Op::Atan:
            return std::atan(a);
        case Op::Sign:
            return sign(a);
        case Op::Trunc:
            return std::trunc(a);
        case Op::Not:
            return a == 0.0f ? 1.0f : 0.0f;
        case Op::Bake:
        case Op::Dynamic:
            return a;
        default:
            return 0.0f;
    }
}

inline float binary(Op op, float a, float b) {
    switch (op) {
        case Op::Add:
            return a + b;
        case Op::Sub:
            return a - b;
        case Op::Mul:
            return a * b;
        case Op::Div:
            return safeDiv(a, b);
        case Op::IDiv:
            return std::trunc(safeDiv(a, b));
        case Op::Min:
            return std::min(a, b);
        case Op::Max:
            return std::max(a, b);
        case Op::Mod:
            return mod(a, b);
        case Op::Pow:
            return safePow(a, b);
        case Op::Atan2:
            return std::atan2(a, b);
        case Op::Step:
            return b < a ? 0.0f : 1.0f;
        case Op::Lt:
            return a < b ? 1.0f : 0.0f;
        case Op::Le:
            return a <= b ? 1.0f : 0.0f;
        case Op::Gt:
            return a > b ? 1.0f : 0.0f;
        case Op::Ge:
            return a >= b ? 1.0f : 0.0f;
        case Op::Eq:
            return a == b ? 1.0f : 0.0f;
        case Op::Ne:
            return a != b ? 1.0f : 0.0f;
        case Op::And:
            return truthy(a) * truthy(b);
        case Op::Or:
            return std::max(truthy(a), truthy(b));
        default:
            return 0.0f;
    }
}

inline float ternary(Op op, float a, float b, float c) {
    switch (op) {
        case Op::Clamp:
            return std::min(std::max(a, b), c);
        case Op::Mix:
            return a * (1.0f - c) + b * c;
        case Op::Smoothstep:
            return smoothstep(a, b, c);
        case Op::Select:
            return a != 0.0f ? b : c;
        default:
            return 0.0f;
    }
}

inline float pattern(Op op, int octaves, float x, float y, float z) {
    switch (op) {
        case Op::Noise:
            return noise3(x, y, z);
        case Op::Snoise:
            return snoise3(x, y, z);
        case Op::Cellnoise:
            return cellnoise3(x, y, z);
        case Op::Fbm:
            return fbm3(x, y, z, octaves);
        case Op::Turbulence:
            return turbulence3(x, y, z, octaves);
        default:
            return 0.0f;
    }
}

}  // namespace mpshade::scalar
