#include "controller/view_lookahead.h"

#include <algorithm>

#include "phases/object_representation.h"

namespace mpshade {

size_t holdingView(std::span<const ObjectViewpoint> views, size_t candidates,
                   const glm::vec3& center, const RangeOptions& range) {
    size_t count = 0;
    while (count < views.size() && views[count].objectToWorld == views[0].objectToWorld) ++count;
    size_t best = 0, bestRun = 0;
    for (size_t c = 0; c <= std::min(candidates, count - 1); ++c) {
        size_t run = 0;
        while (run < count &&
               ObjectRepresentation::checkRange(range, center, views[c].eye, views[c].forward, true,
                                                views[run].eye, views[run].forward)
                       .fiducial == ObjectRepresentation::RangeCheck::None)
            ++run;
        if (run > bestRun) best = c, bestRun = run;
    }
    return best;
}

}  // namespace mpshade
