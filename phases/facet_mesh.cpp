#include "phases/facet_mesh.h"

#include <algorithm>
#include <cmath>

#include <glm/common.hpp>

namespace mpshade {

FixedPointFormat FixedPointFormat::forBounds(const Bounds3& bounds) {
    FixedPointFormat f;
    f.origin = bounds.lo;
    const glm::vec3 extent = glm::max(bounds.hi - bounds.lo, glm::vec3(1e-30f));
    f.step = extent / static_cast<float>(kMax);
    return f;
}

uint16_t FixedPointFormat::quantize(float x, int axis) const {
    const float q = std::round((x - origin[axis]) / step[axis]);
    return static_cast<uint16_t>(std::clamp(q, 0.0f, static_cast<float>(kMax)));
}

size_t FacetMesh::bytes() const {
    size_t b = (qx.size() + qy.size() + qz.size()) * sizeof(uint16_t) +
               (positionIndex.size() + attributeIndex.size()) * sizeof(uint32_t);
    for (const auto& row : attributes.rows) b += row.size() * sizeof(float);
    return b;
}

}  // namespace mpshade
