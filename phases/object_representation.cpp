#include "phases/object_representation.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

namespace mpshade {

uint64_t newRepresentationSerial() {
    static std::atomic<uint64_t> next{1};
    return next.fetch_add(1, std::memory_order_relaxed);
}

bool ObjectRepresentation::inRange(const glm::vec3& eye, const glm::vec3& forward) const {
    return checkRange(eye, forward).fiducial == RangeCheck::None;
}

ObjectRepresentation::RangeCheck ObjectRepresentation::checkRange(const glm::vec3& eye,
                                                                  const glm::vec3& forward) const {
    return checkRange(range, center, representativeEye, representativeForward, frustumCulled, eye,
                      forward);
}

ObjectRepresentation::RangeCheck ObjectRepresentation::checkRange(
    const RangeOptions& range, const glm::vec3& center, const glm::vec3& representativeEye,
    const glm::vec3& representativeForward, bool frustumCulled, const glm::vec3& eye,
    const glm::vec3& forward) {
    RangeCheck c;
    auto degrees = [](float cosine) {
        return glm::degrees(std::acos(std::clamp(cosine, -1.0f, 1.0f)));
    };
    const float turn = glm::dot(forward, representativeForward);
    if (frustumCulled && turn < std::cos(glm::radians(range.angle)))
        return {RangeCheck::ViewDirection, degrees(turn), range.angle};
    const glm::vec3 a = representativeEye - center, b = eye - center;
    const float da = glm::length(a), db = glm::length(b);
    if (!(da > 0.0f) || !(db > 0.0f)) return {RangeCheck::Distance, 0.0f, range.distanceFactor};
    const float ratio = db / da;
    if (ratio > range.distanceFactor || ratio < 1.0f / range.distanceFactor)
        return {RangeCheck::Distance, ratio, range.distanceFactor};
    const float cosine = std::clamp(glm::dot(a, b) / (da * db), -1.0f, 1.0f);
    if (std::acos(cosine) > glm::radians(range.angle))
        return {RangeCheck::AngleAround, degrees(cosine), range.angle};
    return c;
}

void sortUniqueTiles(std::vector<TileRequest>& tiles) {
    std::sort(tiles.begin(), tiles.end(), [](const TileRequest& a, const TileRequest& b) {
        return a.object != b.object ? a.object < b.object : a.key.packed() < b.key.packed();
    });
    tiles.erase(std::unique(tiles.begin(), tiles.end(),
                            [](const TileRequest& a, const TileRequest& b) {
                                return a.object == b.object && a.key == b.key;
                            }),
                tiles.end());
}

}  // namespace mpshade
