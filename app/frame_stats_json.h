// frame_stats_json.h -- parts of a frame's statistics as stats.json writes them, shared by
// `render` and `play`.
#pragma once

#include <nlohmann/json.hpp>

#include "phases/frame_stats.h"
#include "scene/scene.h"

namespace mpshade {

// Every object whose static phase was due: its name, the cause, the fiducial measured
// against its threshold, and whether it was put off (a frame budget, or a frame rendered
// single-phase: nothing is built then).
nlohmann::json staticRunsDueJson(const Scene& scene, const FrameStats& stats);

// A multi-phase frame's figures both commands write into its entry: the phases' seconds
// (static_seconds, of it fill_seconds; warp, raster, shade, resolve), its static runs and
// why, and the tile cache (requested, filled, evicted; resident and pinned bytes).
void addMultiphaseFrameJson(const Scene& scene, const FrameStats& stats, nlohmann::json& entry);

}  // namespace mpshade
