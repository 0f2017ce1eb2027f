#include "shading/lighting.h"

#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

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
        const float denom = ndh * ndh * (a2 - 1.0f) + 1.0f;
        const float D = a2 / (kPi * denom * denom);
        return Cl * (D * ndl * 0.25f);
    }
    // Phong
    const glm::vec3 R = -V + 2.0f * glm::dot(N, V) * N;
    return Cl * scalar::safePow(std::fmax(0.0f, glm::dot(R, L)), param);
}

void shadeLight(Op op, const LightSample& light, const float* const* args, float* const* rgb,
                int m) {
    for (int l = 0; l < m; ++l) {
        const glm::vec3 P(args[0][l], args[1][l], args[2][l]);
        const glm::vec3 N(args[3][l], args[4][l], args[5][l]);
        glm::vec3 V(0.0f);
        float param = 0.0f;
        if (op != Op::Diffuse) {
            V = glm::vec3(args[6][l], args[7][l], args[8][l]);
            param = args[9][l];
        }
        const glm::vec3 c = shadeLightOne(op, light, P, N, V, param);
        rgb[0][l] = c.x;
        rgb[1][l] = c.y;
        rgb[2][l] = c.z;
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
