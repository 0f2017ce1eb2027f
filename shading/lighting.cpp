#include "shading/lighting.h"

#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

#include "geometry/float4.h"
#include "geometry/point_cloud.h"
#include "geometry/ray_scene.h"
#include "shading/scalar_ops.h"

namespace mpshade {
namespace {
constexpr float kPi = 3.14159265358979323846f;

float radicalInverse2(uint32_t i) {
    i = (i << 16u) | (i >> 16u);
    i = ((i & 0x55555555u) << 1u) | ((i & 0xAAAAAAAAu) >> 1u);
    i = ((i & 0x33333333u) << 2u) | ((i & 0xCCCCCCCCu) >> 2u);
    i = ((i & 0x0F0F0F0Fu) << 4u) | ((i & 0xF0F0F0F0u) >> 4u);
    i = ((i & 0x00FF00FFu) << 8u) | ((i & 0xFF00FF00u) >> 8u);
    return static_cast<float>(i) * 2.3283064365386963e-10f;
}

inline void toLight(const LightSample& light, const glm::vec3& P, glm::vec3& L, glm::vec3& Cl) {
    if (light.kind == LightKind::Point) {
        const glm::vec3 d = light.position - P;
        const float d2 = glm::dot(d, d);
        if (!(d2 > 0.0f)) {
            L = glm::vec3(0.0f);
            Cl = glm::vec3(0.0f);
            return;
        }
        L = d / std::sqrt(d2);
        Cl = light.color / d2;
    } else {
        L = light.toLight;
        Cl = light.color;
    }
}

}  // namespace

glm::vec3 shadeLightOne(Op op, const LightSample& light, const glm::vec3& P, const glm::vec3& N,
                        const glm::vec3& V, float param) {
    glm::vec3 L, Cl;
    toLight(light, P, L, Cl);
    const float ndl = std::fmax(0.0f, glm::dot(N, L));
    if (op == Op::Diffuse) return Cl * ndl;
    if (op == Op::Specular) {
        const glm::vec3 h = L + V;
        const float hl = glm::length(h);
        if (!(hl > 0.0f) || ndl <= 0.0f) return glm::vec3(0.0f);
        const float ndh = std::fmax(0.0f, glm::dot(N, h / hl));
        const float r = std::fmin(std::fmax(param, 0.01f), 1.0f);
        const float a2 = r * r * r * r;
        // As in shadeLanes: 1 - ndh^2 as (1 - ndh)(1 + ndh), exact near the peak.
        const float denom = (1.0f - ndh) * (1.0f + ndh) + ndh * ndh * a2;
        const float D = a2 / (kPi * denom * denom);
        return Cl * (D * ndl * 0.25f);
    }
    // Phong
    const glm::vec3 R = -V + 2.0f * glm::dot(N, V) * N;
    return Cl * scalar::safePow(std::fmax(0.0f, glm::dot(R, L)), param);
}

namespace {

// max(0, x) that is 0 for NaN, as std::fmax(0, x) is, without a library call.
inline float positive(float x) {
    return x > 0.0f ? x : 0.0f;
}

// One light over m lanes, with the light's kind and the operation fixed, so the lane loop
// has no branches on them (the formulas are shadeLightOne's).
template <Op kOp, bool kPoint>
void shadeLanes(const LightSample& light, const float* const* args, float* const* rgb, int m) {
    const float* __restrict px = args[0];
    const float* __restrict py = args[1];
    const float* __restrict pz = args[2];
    const float* __restrict nx = args[3];
    const float* __restrict ny = args[4];
    const float* __restrict nz = args[5];
    const float* __restrict vx0 = kOp == Op::Diffuse ? nullptr : args[6];
    const float* __restrict vy0 = kOp == Op::Diffuse ? nullptr : args[7];
    const float* __restrict vz0 = kOp == Op::Diffuse ? nullptr : args[8];
    const float* __restrict pr = kOp == Op::Diffuse ? nullptr : args[9];
    float* __restrict outR = rgb[0];
    float* __restrict outG = rgb[1];
    float* __restrict outB = rgb[2];
    const float lpx = light.position.x, lpy = light.position.y, lpz = light.position.z;
    const float tlx = light.toLight.x, tly = light.toLight.y, tlz = light.toLight.z;
    const float ccr = light.color.x, ccg = light.color.y, ccb = light.color.z;
    // Branch-free (selects, and divisions by safe denominators), so the loop vectorizes.
    for (int l = 0; l < m; ++l) {
        float Lx, Ly, Lz, cr, cg, cb;
        if constexpr (kPoint) {
            const float dx = lpx - px[l], dy = lpy - py[l], dz = lpz - pz[l];
            const float d2 = dx * dx + dy * dy + dz * dz;
            const bool ok = d2 > 0.0f;
            const float safe = ok ? d2 : 1.0f;
            const float root = 1.0f / std::sqrt(safe), recip = 1.0f / safe;
            const float inv = ok ? root : 0.0f;
            const float fall = ok ? recip : 0.0f;
            Lx = dx * inv, Ly = dy * inv, Lz = dz * inv;
            cr = ccr * fall, cg = ccg * fall, cb = ccb * fall;
        } else {
            Lx = tlx, Ly = tly, Lz = tlz;
            cr = ccr, cg = ccg, cb = ccb;
        }
        const float ndl = positive(nx[l] * Lx + ny[l] * Ly + nz[l] * Lz);
        float f;
        if constexpr (kOp == Op::Diffuse) {
            f = ndl;
        } else if constexpr (kOp == Op::Specular) {
            const float hx = Lx + vx0[l], hy = Ly + vy0[l], hz = Lz + vz0[l];
            const float hl = std::sqrt(hx * hx + hy * hy + hz * hz);
            const bool ok = hl > 0.0f && ndl > 0.0f;
            const float ndh = positive((nx[l] * hx + ny[l] * hy + nz[l] * hz) / (ok ? hl : 1.0f));
            const float param = pr[l];
            const float r = std::min(param > 0.01f ? param : 0.01f, 1.0f);
            const float a2 = r * r * r * r;
            // 1 - ndh^2 (1 - a2), with 1 - ndh^2 as (1 - ndh)(1 + ndh): exact near the
            // peak (Sterbenz), where the plain form cancels to 0 for a2 below float epsilon
            // and D became infinite at the roughness floor.
            const float denom = (1.0f - ndh) * (1.0f + ndh) + ndh * ndh * a2;
            const float D = a2 / (kPi * denom * denom);
            f = ok ? D * ndl * 0.25f : 0.0f;
        } else {
            const float vx = vx0[l], vy = vy0[l], vz = vz0[l];
            const float nv2 = 2.0f * (nx[l] * vx + ny[l] * vy + nz[l] * vz);
            const float rx = -vx + nv2 * nx[l], ry = -vy + nv2 * ny[l], rz = -vz + nv2 * nz[l];
            f = scalar::safePow(positive(rx * Lx + ry * Ly + rz * Lz), pr[l]);
        }
        outR[l] = cr * f;
        outG[l] = cg * f;
        outB[l] = cb * f;
    }
}

// shadeLanes for diffuse and specular, four lanes at a time in vector registers (the
// compiler does not vectorize the loop above), with the same operations in the same order:
// the results are bitwise those of the scalar loop, which takes the last m % 4 lanes.
template <Op kOp, bool kPoint>
int shadeFourLanes(const LightSample& light, const float* const* args, float* const* rgb, int m) {
    static_assert(kOp == Op::Diffuse || kOp == Op::Specular);
    const Float4 zero = splatFloat4(0.0f), one = splatFloat4(1.0f);
    const Float4 lpx = splatFloat4(light.position.x), lpy = splatFloat4(light.position.y),
                 lpz = splatFloat4(light.position.z);
    const Float4 ccr = splatFloat4(light.color.x), ccg = splatFloat4(light.color.y),
                 ccb = splatFloat4(light.color.z);
    auto positive4 = [&](Float4 x) { return x > zero ? x : zero; };
    const int whole = m & ~3;
    for (int l = 0; l < whole; l += 4) {
        Float4 Lx, Ly, Lz, cr, cg, cb;
        if constexpr (kPoint) {
            const Float4 dx = lpx - loadFloat4(args[0] + l), dy = lpy - loadFloat4(args[1] + l),
                         dz = lpz - loadFloat4(args[2] + l);
            const Float4 d2 = dx * dx + dy * dy + dz * dz;
            const auto ok = d2 > zero;
            const Float4 safe = ok ? d2 : one;
            const Float4 root = one / sqrtFloat4(safe), recip = one / safe;
            const Float4 inv = ok ? root : zero, fall = ok ? recip : zero;
            Lx = dx * inv, Ly = dy * inv, Lz = dz * inv;
            cr = ccr * fall, cg = ccg * fall, cb = ccb * fall;
        } else {
            Lx = splatFloat4(light.toLight.x), Ly = splatFloat4(light.toLight.y),
            Lz = splatFloat4(light.toLight.z);
            cr = ccr, cg = ccg, cb = ccb;
        }
        const Float4 nx = loadFloat4(args[3] + l), ny = loadFloat4(args[4] + l),
                     nz = loadFloat4(args[5] + l);
        const Float4 ndl = positive4(nx * Lx + ny * Ly + nz * Lz);
        Float4 f;
        if constexpr (kOp == Op::Diffuse) {
            f = ndl;
        } else {
            const Float4 hx = Lx + loadFloat4(args[6] + l), hy = Ly + loadFloat4(args[7] + l),
                         hz = Lz + loadFloat4(args[8] + l);
            const Float4 hl = sqrtFloat4(hx * hx + hy * hy + hz * hz);
            const auto ok = (hl > zero) & (ndl > zero);
            const Float4 ndh = positive4((nx * hx + ny * hy + nz * hz) / (ok ? hl : one));
            const Float4 param = loadFloat4(args[9] + l), floor = splatFloat4(0.01f);
            const Float4 p = param > floor ? param : floor;
            const Float4 r = one < p ? one : p;  // std::min(p, 1)
            const Float4 a2 = r * r * r * r;
            const Float4 denom = (one - ndh) * (one + ndh) + ndh * ndh * a2;
            const Float4 D = a2 / (splatFloat4(kPi) * denom * denom);
            f = ok ? D * ndl * splatFloat4(0.25f) : zero;
        }
        storeFloat4(rgb[0] + l, cr * f);
        storeFloat4(rgb[1] + l, cg * f);
        storeFloat4(rgb[2] + l, cb * f);
    }
    return whole;
}

template <Op kOp>
void shadeLanes(const LightSample& light, const float* const* args, float* const* rgb, int m) {
    const bool point = light.kind == LightKind::Point;
    int done = 0;
    if constexpr (kOp == Op::Diffuse || kOp == Op::Specular)
        done = point ? shadeFourLanes<kOp, true>(light, args, rgb, m)
                     : shadeFourLanes<kOp, false>(light, args, rgb, m);
    if (done == m) return;
    const float* rest[10] = {};
    for (int k = 0; k < (kOp == Op::Diffuse ? 6 : 10); ++k) rest[k] = args[k] + done;
    float* restRgb[3] = {rgb[0] + done, rgb[1] + done, rgb[2] + done};
    if (point)
        shadeLanes<kOp, true>(light, rest, restRgb, m - done);
    else
        shadeLanes<kOp, false>(light, rest, restRgb, m - done);
}

}  // namespace

void shadeLight(Op op, const LightSample& light, const float* const* args, float* const* rgb,
                int m) {
    switch (op) {
        case Op::Diffuse:
            return shadeLanes<Op::Diffuse>(light, args, rgb, m);
        case Op::Specular:
            return shadeLanes<Op::Specular>(light, args, rgb, m);
        default:
            return shadeLanes<Op::Phong>(light, args, rgb, m);
    }
}

uint64_t occlusionLanes(const SurfaceRayScene* occluder, float bias, int rays,
                        const float* const* args, float* out, int m) {
    if (!occluder) {
        for (int l = 0; l < m; ++l) out[l] = 1.0f;
        return 0;
    }
    uint64_t traced = 0;
    for (int l = 0; l < m; ++l) {
        const glm::vec3 P(args[0][l], args[1][l], args[2][l]);
        glm::vec3 N(args[3][l], args[4][l], args[5][l]);
        const float len = glm::length(N);
        if (!(len > 0.0f) || !std::isfinite(len) || !std::isfinite(P.x + P.y + P.z)) {
            out[l] = 1.0f;
            continue;
        }
        N /= len;
        glm::vec3 T, B;
        orthonormalBasis(N, T, B);
        const glm::vec3 origin = P + bias * N;
        int open = 0;
        for (int i = 0; i < rays; ++i) {
            // Hammersley point -> cosine-weighted direction (Malley's method).
            const float u1 = (static_cast<float>(i) + 0.5f) / static_cast<float>(rays);
            const float u2 = radicalInverse2(static_cast<uint32_t>(i));
            const float r = std::sqrt(u1), phi = 2.0f * kPi * u2;
            const glm::vec3 dir = r * std::cos(phi) * T + r * std::sin(phi) * B +
                                  std::sqrt(std::fmax(0.0f, 1.0f - u1)) * N;
            if (!occluder->occluded(origin, dir, 0.0f, std::numeric_limits<float>::infinity()))
                ++open;
        }
        traced += static_cast<uint64_t>(rays);
        out[l] = static_cast<float>(open) / static_cast<float>(rays);
    }
    return traced;
}

}  // namespace mpshade
