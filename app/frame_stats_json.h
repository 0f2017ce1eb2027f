// frame_stats_json.h -- a frame's statistics as stats.json writes them: every frame entry of
// `render` and `play`, and render's per-object reports, are made here and nowhere else
// (docs/playback.md and the README list the keys).
#pragma once

#include <nlohmann/json.hpp>

#include "controller/multiphase_renderer.h"
#include "controller/playback.h"
#include "phases/frame_stats.h"
#include "phases/image.h"
#include "phases/image_compare.h"
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

// `render`'s entry for a frame: what every frame reports (time, samples, rays, shading),
// and with `multiphase` the multi-phase figures, with the facets per pixel `image` covers.
nlohmann::json renderFrameJson(const Scene& scene, const FrameStats& stats, bool multiphase,
                               const Image& image);

// `render --compare`: the reference's frame against the multi-phase one (`error`), and the
// speed ratio of their wall times.
nlohmann::json referenceFrameJson(const FrameStats& multiphase, const FrameStats& reference,
                                  const ImageError& error);

// `play`'s entry for a frame played at `quality` (spp: the request's samples per pixel,
// for a step that keeps them); writeSeconds: writing its images, outside the frame.
nlohmann::json playFrameJson(const Scene& scene, const FrameStats& stats,
                             const PlaybackQuality& quality, int spp, double writeSeconds);

// `render`'s per-object reports: representation and why, static runs and time, facets,
// tiles and bytes.
nlohmann::json objectReportsJson(const MultiphaseRenderer& renderer);

}  // namespace mpshade
