#include "geometry/analytic_shapes.h"

#include <cmath>

#include <glm/geometric.hpp>

namespace mpshade {
namespace {
constexpr float kTwoPi = 6.28318530717958647692f;
constexpr float kPi = 3.14159265358979323846f;
}  // namespace

SurfaceSample Sphere::evaluate(int, float u, float v) const {
    const float phi = kTwoPi * u;
    const float theta = kPi * (v - 0.5f);  // latitude in [-pi/2, pi/2]
    const float cp = std::cos(phi), sp = std::sin(phi);
    const float ct = std::cos(theta), st = std::sin(theta);
    SurfaceSample s;
    const glm::vec3 dir(ct * cp, st, -ct * sp);
    s.P = radius * dir;
    s.dPdu = radius * kTwoPi * glm::vec3(-ct * sp, 0.0f, -ct * cp);
    s.dPdv = radius * kPi * glm::vec3(-st * cp, ct, st * sp);
    // The analytic normal is exact everywhere, poles included, where dPdu vanishes.
    s.N = s.Ng = glm::normalize(dir);
    s.s = u;
    s.t = v;
    return s;
}

Bounds3 Sphere::bounds() const {
    return {glm::vec3(-radius), glm::vec3(radius)};
}

SurfaceSample Torus::evaluate(int, float u, float v) const {
    const float phi = kTwoPi * u;
    const float psi = kTwoPi * v;
    const float cp = std::cos(phi), sp = std::sin(phi);
    const float cs = std::cos(psi), ss = std::sin(psi);
    const float ring = major + minor * cs;
    SurfaceSample s;
    s.P = glm::vec3(ring * cp, minor * ss, -ring * sp);
    s.dPdu = kTwoPi * ring * glm::vec3(-sp, 0.0f, -cp);
    s.dPdv = kTwoPi * minor * glm::vec3(-ss * cp, cs, ss * sp);
    s.N = s.Ng = glm::vec3(cs * cp, ss, -cs * sp);
    s.s = u;
    s.t = v;
    return s;
}

Bounds3 Torus::bounds() const {
    const float r = major + minor;
    return {glm::vec3(-r, -minor, -r), glm::vec3(r, minor, r)};
}

Bounds3 Plane::bounds() const {
    return {glm::vec3(-0.5f * width, 0.0f, -0.5f * depth),
            glm::vec3(0.5f * width, 0.0f, 0.5f * depth)};
}

}  // namespace mpshade
