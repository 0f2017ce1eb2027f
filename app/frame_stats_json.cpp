#include "app/frame_stats_json.h"

namespace mpshade {

nlohmann::json staticRunsDueJson(const Scene& scene, const FrameStats& stats) {
    nlohmann::json due = nlohmann::json::array();
    for (const StaticRunDue& d : stats.staticRunsDue) {
        nlohmann::json e = {{"object", scene.objects[d.object].name},
                            {"cause", staticRunCauseName(d.cause)},
                            {"deferred", d.deferred || stats.singlePhase}};
        if (d.cause != StaticRunDue::FirstSeen) {
            e["measured"] = d.measured;
            e["threshold"] = d.threshold;
        }
        due.push_back(std::move(e));
    }
    return due;
}

}  // namespace mpshade
