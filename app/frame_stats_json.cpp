#include "app/frame_stats_json.h"

namespace mpshade {

void addMultiphaseFrameJson(const Scene& scene, const FrameStats& stats, nlohmann::json& entry) {
    entry["static_seconds"] = stats.staticSeconds;
    entry["fill_seconds"] = stats.fillSeconds;
    entry["warp_seconds"] = stats.warpSeconds;
    entry["raster_seconds"] = stats.rasterSeconds;
    entry["shade_seconds"] = stats.shadeSeconds;
    entry["resolve_seconds"] = stats.resolveSeconds;
    entry["static_runs"] = stats.staticRuns;
    entry["static_runs_due"] = staticRunsDueJson(scene, stats);
    entry["tiles_requested"] = stats.tilesRequested;
    entry["tiles_filled"] = stats.tilesFilled;
    entry["tiles_evicted"] = stats.tilesEvicted;
    entry["resident_bytes"] = stats.residentBytes;
    entry["resident_pinned_bytes"] = stats.residentPinnedBytes;
}

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
