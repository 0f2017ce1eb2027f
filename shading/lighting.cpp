#include "shading/lighting.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include <glm/geometric.hpp>

#include "geometry/error.h"
#include "geometry/float4.h"
#include "geometry/point_cloud.h"
#include "geometry/ray_scene.h"
#include "shading/light_lanes.h"
#include "shading/lighting_avx2.h"
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

// One light over m lanes: four at a time in vector registers (the compiler did not
// vectorize the one-lane loop) for diffuse and specular, the rest one at a time. Phong's
// power is a library call: one lane at a time.
template <Op kOp, bool kPoint, bool kNegV, bool kEpi>
void shadeLanes(const LightSample& light, const float* const* args, float* const* rgb, int m,
                const LightEpilogue* epilogue) {
    int l = 0;
    if constexpr (kOp != Op::Phong)
        for (; l + 4 <= m; l += 4)
            shadeLightLanes<kOp, kPoint, Float4, kNegV, kEpi>(light, args, rgb, l, epilogue);
    for (; l < m; ++l)
        shadeLightLanes<kOp, kPoint, float, kNegV, kEpi>(light, args, rgb, l, epilogue);
}

template <Op kOp, bool kNegV, bool kEpi>
void shadeLanes(const LightSample& light, const float* const* args, float* const* rgb, int m,
                const LightEpilogue* epilogue) {
    if (light.kind == LightKind::Point)
        shadeLanes<kOp, true, kNegV, kEpi>(light, args, rgb, m, epilogue);
    else
        shadeLanes<kOp, false, kNegV, kEpi>(light, args, rgb, m, epilogue);
}

template <Op kOp>
void shadeLanes(const LightSample& light, const float* const* args, float* const* rgb, int m,
                bool negatedView, bool baseline, const LightEpilogue* epilogue) {
    MPSHADE_CHECK(!negatedView || kOp == Op::Specular);
    static const bool avx2 = shadeLightAvx2Available();
    if (kOp != Op::Phong && avx2 && !baseline)
        return shadeLightAvx2(kOp, light, args, rgb, m, negatedView, epilogue);
    if constexpr (kOp == Op::Specular)
        if (negatedView)
            return epilogue ? shadeLanes<kOp, true, true>(light, args, rgb, m, epilogue)
                            : shadeLanes<kOp, true, false>(light, args, rgb, m, epilogue);
    epilogue ? shadeLanes<kOp, false, true>(light, args, rgb, m, epilogue)
             : shadeLanes<kOp, false, false>(light, args, rgb, m, epilogue);
}

void shadeLightWith(Op op, const LightSample& light, const float* const* args, float* const* rgb,
                    int m, bool negatedView, bool baseline, const LightEpilogue* epilogue) {
    switch (op) {
        case Op::Diffuse:
            return shadeLanes<Op::Diffuse>(light, args, rgb, m, negatedView, baseline, epilogue);
        case Op::Specular:
            return shadeLanes<Op::Specular>(light, args, rgb, m, negatedView, baseline, epilogue);
        default:
            return shadeLanes<Op::Phong>(light, args, rgb, m, negatedView, baseline, epilogue);
    }
}

}  // namespace

void shadeLight(Op op, const LightSample& light, const float* const* args, float* const* rgb, int m,
                bool negatedView, const LightEpilogue* epilogue) {
    shadeLightWith(op, light, args, rgb, m, negatedView, false, epilogue);
}

void shadeLightBaseline(Op op, const LightSample& light, const float* const* args,
                        float* const* rgb, int m, bool negatedView, const LightEpilogue* epilogue) {
    shadeLightWith(op, light, args, rgb, m, negatedView, true, epilogue);
}

uint64_t occlusionLanes(const SurfaceRayScene* occluder, float bias, int rays,
                        const float* const* args, float* out, int m, const StopSignal* stop) {
    if (!occluder) {
        for (int l = 0; l < m; ++l) out[l] = 1.0f;
        return 0;
    }
    // Ray i of every lane together: neighbouring points (a tile's texels, a band's samples)
    // send it in nearly one direction from nearly one place, so each such set goes to
    // Embree as one coherent stream, traced in packets.
    constexpr int kChunk = 64;
    float frame[9][kChunk];  // T, B, N per lane, rows
    float org[3][kChunk], dir[3][kChunk];
    uint8_t valid[kChunk], blocked[kChunk];
    int open[kChunk];
    const float* const orgRows[3] = {org[0], org[1], org[2]};
    const float* const dirRows[3] = {dir[0], dir[1], dir[2]};
    uint64_t traced = 0;
    for (int first = 0; first < m; first += kChunk) {
        const int count = std::min(kChunk, m - first);
        int active = 0;
        for (int k = 0; k < count; ++k) {
            const int l = first + k;
            const glm::vec3 P(args[0][l], args[1][l], args[2][l]);
            glm::vec3 N(args[3][l], args[4][l], args[5][l]);
            const float len = glm::length(N);
            valid[k] = (len > 0.0f) && std::isfinite(len) && std::isfinite(P.x + P.y + P.z);
            open[k] = 0;
            if (!valid[k]) continue;
            ++active;
            N /= len;
            glm::vec3 T, B;
            orthonormalBasis(N, T, B);
            const glm::vec3 origin = P + bias * N;
            for (int c = 0; c < 3; ++c) {
                org[c][k] = origin[c];
                frame[c][k] = T[c], frame[3 + c][k] = B[c], frame[6 + c][k] = N[c];
            }
        }
        for (int i = 0; i < rays && active > 0; ++i) {
            if (stop && stop->stopped()) return traced;
            // Hammersley point -> cosine-weighted direction (Malley's method).
            const float u1 = (static_cast<float>(i) + 0.5f) / static_cast<float>(rays);
            const float u2 = radicalInverse2(static_cast<uint32_t>(i));
            const float r = std::sqrt(u1), phi = 2.0f * kPi * u2;
            const float a = r * std::cos(phi), b = r * std::sin(phi);
            const float z = std::sqrt(std::fmax(0.0f, 1.0f - u1));
            for (int k = 0; k < count; ++k)
                for (int c = 0; c < 3; ++c)
                    dir[c][k] = a * frame[c][k] + b * frame[3 + c][k] + z * frame[6 + c][k];
            occluder->occluded(orgRows, dirRows, valid, count, 0.0f,
                               std::numeric_limits<float>::infinity(), blocked);
            for (int k = 0; k < count; ++k) open[k] += blocked[k] ? 0 : 1;
        }
        for (int k = 0; k < count; ++k)
            out[first + k] =
                valid[k] ? static_cast<float>(open[k]) / static_cast<float>(rays) : 1.0f;
        traced += static_cast<uint64_t>(active) * static_cast<uint64_t>(rays);
    }
    return traced;
}

}  // namespace mpshade
