// light_lanes.h -- diffuse and specular light over lanes of points, one lane (float), four
// (Float4) or, in a file built for AVX2, eight at a time: the same operations in the same
// order whatever the width, so a lane's value is the same bits at every width (and
// shadeLightOne's, lighting.h, to rounding). Internal linkage: each file that includes it compiles
// its own copy for its own instruction set (lighting.cpp for the baseline, lighting_avx2.cpp for
// AVX2). A file adding a lane type declares its splat, load, store and root before including.
#pragma once

#include <cmath>
#include <type_traits>

#include "geometry/float4.h"
#include "shading/interpreter.h"
#include "shading/scalar_ops.h"

namespace mpshade {
// NOLINTNEXTLINE(cert-dcl59-cpp,google-build-namespaces): internal linkage on purpose (above)
namespace {

constexpr float kLanePi = 3.14159265358979323846f;

// The lane operations the formulas need, for one lane (float) or four (Float4), so both
// run the same operations in the same order and agree bitwise.
inline float splat(float x, float) {
    return x;
}
inline Float4 splat(float x, Float4) {
    return splatFloat4(x);
}
inline float load(const float* p, float) {
    return *p;
}
inline Float4 load(const float* p, Float4) {
    return loadFloat4(p);
}
inline void store(float* p, float v) {
    *p = v;
}
inline void store(float* p, Float4 v) {
    storeFloat4(p, v);
}
inline float root(float x) {
    return std::sqrt(x);
}
inline Float4 root(Float4 x) {
    return sqrtFloat4(x);
}

// Lanes [l, l + width of V) of one light, with the light's kind and the operation fixed:
// branch-free (selects, and divisions by safe denominators). The formulas are
// shadeLightOne's; max(0, x) is a select that is 0 for NaN, as std::fmax(0, x) is.
// kNegV (Specular): args 6-8 hold -V, so L + V is L - args, the very bits a pass negating
// them first would give (x + -y is x - y in IEEE arithmetic; only a NaN's sign may differ).
// kEpilogue: the light's value goes through `epilogue` (interpreter.h) before it is stored.
template <Op kOp, bool kPoint, typename V, bool kNegV = false, bool kEpilogue = false>
inline void shadeLightLanes(const LightSample& light, const float* const* args, float* const* rgb,
                            int l, const LightEpilogue* epilogue = nullptr) {
    const V zero = splat(0.0f, V{}), one = splat(1.0f, V{});
    auto positive = [&](V x) { return x > zero ? x : zero; };
    V Lx, Ly, Lz, cr, cg, cb;
    if constexpr (kPoint) {
        const V dx = splat(light.position.x, V{}) - load(args[0] + l, V{});
        const V dy = splat(light.position.y, V{}) - load(args[1] + l, V{});
        const V dz = splat(light.position.z, V{}) - load(args[2] + l, V{});
        const V d2 = dx * dx + dy * dy + dz * dz;
        const auto ok = d2 > zero;
        const V safe = ok ? d2 : one;
        const V rootInv = one / root(safe), recip = one / safe;
        const V inv = ok ? rootInv : zero, fall = ok ? recip : zero;
        Lx = dx * inv, Ly = dy * inv, Lz = dz * inv;
        cr = splat(light.color.x, V{}) * fall, cg = splat(light.color.y, V{}) * fall,
        cb = splat(light.color.z, V{}) * fall;
    } else {
        Lx = splat(light.toLight.x, V{}), Ly = splat(light.toLight.y, V{}),
        Lz = splat(light.toLight.z, V{});
        cr = splat(light.color.x, V{}), cg = splat(light.color.y, V{}),
        cb = splat(light.color.z, V{});
    }
    const V nx = load(args[3] + l, V{}), ny = load(args[4] + l, V{}), nz = load(args[5] + l, V{});
    const V ndl = positive(nx * Lx + ny * Ly + nz * Lz);
    V f;
    if constexpr (kOp == Op::Diffuse) {
        f = ndl;
    } else if constexpr (kOp == Op::Specular) {
        V hx, hy, hz;
        if constexpr (kNegV) {
            hx = Lx - load(args[6] + l, V{}), hy = Ly - load(args[7] + l, V{}),
            hz = Lz - load(args[8] + l, V{});
        } else {
            hx = Lx + load(args[6] + l, V{}), hy = Ly + load(args[7] + l, V{}),
            hz = Lz + load(args[8] + l, V{});
        }
        const V hl = root(hx * hx + hy * hy + hz * hz);
        const auto ok = (hl > zero) & (ndl > zero);
        const V ndh = positive((nx * hx + ny * hy + nz * hz) / (ok ? hl : one));
        const V param = load(args[9] + l, V{}), floor = splat(0.01f, V{});
        const V clamped = param > floor ? param : floor;
        const V r = one < clamped ? one : clamped;  // std::min(clamped, 1)
        const V a2 = r * r * r * r;
        // 1 - ndh^2 (1 - a2), with 1 - ndh^2 as (1 - ndh)(1 + ndh): exact near the peak
        // (Sterbenz), where the plain form cancels to 0 for a2 below float epsilon and D
        // became infinite at the roughness floor.
        const V denom = (one - ndh) * (one + ndh) + ndh * ndh * a2;
        const V D = a2 / (splat(kLanePi, V{}) * denom * denom);
        f = ok ? D * ndl * splat(0.25f, V{}) : zero;
    } else {
        const V vx = load(args[6] + l, V{}), vy = load(args[7] + l, V{}),
                vz = load(args[8] + l, V{});
        const V nv2 = splat(2.0f, V{}) * (nx * vx + ny * vy + nz * vz);
        const V rx = -vx + nv2 * nx, ry = -vy + nv2 * ny, rz = -vz + nv2 * nz;
        if constexpr (std::is_same_v<V, float>) {
            f = scalar::safePow(positive(rx * Lx + ry * Ly + rz * Lz), load(args[9] + l, V{}));
        }
    }
    const V channel[3] = {cr * f, cg * f, cb * f};
    for (int c = 0; c < 3; ++c) {
        V value = channel[c];
        if constexpr (kEpilogue) {
            // The shader's mul(scale, light) then add(base, product): each rounded alone.
            if (epilogue->scale[c]) value = load(epilogue->scale[c] + l, V{}) * value;
            value = load(epilogue->base[c] + l, V{}) + value;
        }
        store(rgb[c] + l, value);
    }
}

}  // namespace
}  // namespace mpshade
