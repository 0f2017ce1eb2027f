#include "phases/object_representation.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

namespace mpshade {

bool ObjectRepresentation::inRange(const glm::vec3& eye, const glm::vec3& forward) const {
    if (frustumCulled &&
        glm::dot(forward, representativeForward) < std::cos(glm::radians(range.angle)))
        return false;
    const glm::vec3 a = representativeEye - center, b = eye - center;
    const float da = glm::length(a), db = glm::length(b);
    if (!(da > 0.0f) || !(db > 0.0f)) return false;
    const float ratio = db / da;
    if (ratio > range.distanceFactor || ratio < 1.0f / range.distanceFactor) return false;
    const float cosine = std::clamp(glm::dot(a, b) / (da * db), -1.0f, 1.0f);
    return std::acos(cosine) <= glm::radians(range.angle);
}

}  // namespace mpshade
