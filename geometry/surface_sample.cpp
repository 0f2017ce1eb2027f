#include "geometry/surface_sample.h"

#include <cmath>

#include <glm/geometric.hpp>

namespace mpshade {

void Bounds3::extend(const glm::vec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
}

void Bounds3::extend(const Bounds3& b) {
    if (b.empty()) return;
    extend(b.lo);
    extend(b.hi);
}

float Bounds3::diagonal() const {
    return empty() ? 0.0f : glm::length(hi - lo);
}

glm::vec3 normalFromDerivatives(const glm::vec3& dPdu, const glm::vec3& dPdv,
                                const glm::vec3& fallback) {
    glm::vec3 c = glm::cross(dPdu, dPdv);
    float len2 = glm::dot(c, c);
    // Degenerate when the frame has (nearly) collapsed relative to its larger derivative:
    // a vanishing derivative at a pole or collapsed patch edge is rounding noise, and its
    // direction means nothing even though the cross product is not exactly zero.
    const float big = std::fmax(glm::dot(dPdu, dPdu), glm::dot(dPdv, dPdv));
    if (!(len2 > 1e-10f * big * big) || !(len2 > 0.0f)) return fallback;
    return c / std::sqrt(len2);
}

}  // namespace mpshade
