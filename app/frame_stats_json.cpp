#include "app/frame_stats_json.h"

#include "controller/cost_profile.h"

namespace mpshade {

void addMultiphaseFrameJson(const Scene& scene, const FrameStats& stats, nlohmann::json& entry) {
    entry["static_seconds"] = stats.staticWork.seconds;
    entry["fill_seconds"] = stats.staticWork.fillSeconds;
    entry["warp_seconds"] = stats.dynamic.warpSeconds;
    entry["raster_seconds"] = stats.dynamic.rasterSeconds;
    entry["shade_seconds"] = stats.dynamic.shadeSeconds;
    const DynamicFrameStats::ShadeParts& parts = stats.dynamic.shadeParts;
    entry["shade_cpu_seconds"] = {{"points", parts.points},
                                  {"interpolate", parts.interpolate},
                                  {"probe", parts.probe},
                                  {"kernel", parts.kernel},
                                  {"composite", parts.composite}};
    entry["resolve_seconds"] = stats.dynamic.resolveSeconds;
    entry["static_runs"] = stats.staticWork.work.runs;
    entry["static_runs_from_store"] = stats.staticWork.work.representationsLoaded;
    entry["static_runs_due"] = staticRunsDueJson(scene, stats);
    entry["tiles_requested"] = stats.tiles.missing;
    entry["tiles_filled"] = stats.staticWork.work.tilesFilled;
    entry["tiles_from_store"] = stats.staticWork.work.tilesLoaded;
    entry["tiles_evicted"] = stats.tiles.evicted;
    entry["resident_bytes"] = stats.tiles.residentBytes;
    entry["resident_pinned_bytes"] = stats.tiles.residentPinnedBytes;
    if (stats.footprintCalibration.objects > 0)
        entry["footprint_calibration"] = {{"objects", stats.footprintCalibration.objects},
                                          {"seconds", stats.footprintCalibration.seconds}};
}

nlohmann::json staticRunsDueJson(const Scene& scene, const FrameStats& stats) {
    nlohmann::json due = nlohmann::json::array();
    for (const StaticRunDue& d : stats.staticWork.due) {
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

nlohmann::json renderFrameJson(const Scene& scene, const FrameStats& stats, bool multiphase,
                               const Image& image) {
    nlohmann::json entry = {{"index", stats.index},
                            {"time", stats.time},
                            {"wall_seconds", stats.wallSeconds},
                            {"samples", stats.samples},
                            {"rays", stats.rays},
                            {"occlusion_rays", stats.occlusionRays},
                            {"shaded_points", stats.shadedPoints},
                            {"shader_instructions", stats.shaderInstructions},
                            {"nonfinite_samples", stats.nonFiniteSamples}};
    if (!multiphase) return entry;
    // Four running sums, not one: a chain of dependent additions over a 1280x720 frame's
    // alphas had been 1.4% of a render's CPU.
    double part[4] = {0.0, 0.0, 0.0, 0.0};
    const size_t pixels = image.rgba.size() / 4;
    size_t p = 0;
    for (; p + 4 <= pixels; p += 4)
        for (int k = 0; k < 4; ++k) part[k] += image.rgba[4 * (p + k) + 3];
    for (; p < pixels; ++p) part[0] += image.rgba[4 * p + 3];
    const double covered = (part[0] + part[1]) + (part[2] + part[3]);
    entry["single_phase"] = stats.singlePhase;
    addMultiphaseFrameJson(scene, stats, entry);
    entry["static_instructions"] = stats.staticWork.work.instructions;
    entry["objects_drawn"] = stats.objectsDrawn;
    entry["facets"] = stats.dynamic.facets;
    entry["facet_bytes"] = stats.dynamic.facetBytes;
    entry["facets_rasterized"] = stats.dynamic.raster.facetsBinned;
    entry["covered_pixels"] = covered;
    entry["facets_per_covered_pixel"] =
        covered > 0.0 ? static_cast<double>(stats.dynamic.raster.facetsBinned) / covered : 0.0;
    entry["fragments"] = stats.dynamic.raster.fragments;
    entry["vertices_warped"] = stats.dynamic.verticesWarped;
    entry["shade_passes"] = stats.dynamic.shadePasses;
    entry["probes"] = stats.dynamic.probes;
    entry["probe_fallbacks"] = stats.dynamic.probeFallbacks;
    entry["view_reused"] = stats.dynamic.viewReused;
    entry["points_replayed"] = stats.dynamic.pointsReplayed;
    entry["tiles_from_children"] = stats.staticWork.work.tilesFromChildren;
    entry["texels_filled"] = stats.staticWork.work.texelsFilled;
    entry["resident_tiles"] = stats.tiles.resident;
    return entry;
}

nlohmann::json referenceFrameJson(const FrameStats& multiphase, const FrameStats& reference,
                                  const ImageError& error) {
    return {{"wall_seconds", reference.wallSeconds},
            {"psnr_db", error.psnr},
            {"rmse", error.rmse},
            {"max_abs_error", error.maxAbs},
            {"coverage_difference", error.coverageDiff},
            {"speedup",
             multiphase.wallSeconds > 0 ? reference.wallSeconds / multiphase.wallSeconds : 0.0}};
}

nlohmann::json playFrameJson(const Scene& scene, const FrameStats& s,
                             const PlaybackQuality& quality, int spp, double writeSeconds) {
    nlohmann::json entry = {
        {"index", s.index},
        {"time", s.time},
        {"wall_seconds", s.wallSeconds},
        {"budget_seconds", s.budget.seconds},
        {"deadline_met", s.budget.deadlineMet},
        {"write_seconds", writeSeconds},
        {"built_ahead", s.budget.builtAhead},
        {"quality",
         {{"level", quality.level},
          {"shading_rate", shadingRateName(quality.step.rate)},
          {"footprint_scale", quality.step.footprintScale},
          {"samples_per_pixel",
           quality.step.samplesPerPixel > 0 ? quality.step.samplesPerPixel : spp},
          {"probes", s.dynamic.probes},
          {"probe_fallbacks", s.dynamic.probeFallbacks},
          {"older_representations", s.budget.rebuildsDeferred}}},
        {"deferred",
         {{"tiles", s.budget.tilesDeferred},
          {"rebuilds", s.budget.rebuildsDeferred},
          {"rebuilds_in_background", s.budget.rebuildsInBackground},
          {"fills_stopped", s.budget.fillsStopped}}},
        {"probe_hits", s.dynamic.probes - s.dynamic.probeFallbacks},
        {"view_reused", s.dynamic.viewReused},
        {"points_replayed", s.dynamic.pointsReplayed},
        {"controller_seconds", s.controllerSeconds},
        {"prefetch",
         {{"predicted", s.prefetch.predicted},
          {"abandoned", s.prefetch.abandoned},
          {"adjacent", s.prefetch.adjacent},
          {"filled", s.prefetch.filled},
          {"used", s.prefetch.used},
          {"wasted", s.prefetch.wasted},
          {"seconds", s.prefetch.seconds}}},
        {"background",
         {{"filled", s.background.tilesFilled},
          {"evicted", s.background.tilesEvicted},
          {"seconds", s.background.seconds},
          {"rebuilds", s.background.rebuilds},
          {"rebuild_cpu_seconds", s.background.rebuildSeconds}}},
        {"shaded_points", s.shadedPoints}};
    if (s.refine.ran) {
        // Per step from the frame's own up (its rate and footprint, at the frame's samples
        // per pixel): the share of the image's pixels there.
        nlohmann::json share = nlohmann::json::array(), refined = nlohmann::json::array();
        uint64_t pixels = 0;
        for (int k = 0; k < s.refine.steps; ++k) pixels += s.refine.pixelsAt[k];
        for (int k = 0; k < s.refine.steps; ++k) {
            share.push_back(
                {{"shading_rate", shadingRateName(s.refine.rateAt[k])},
                 {"footprint_scale", s.refine.footprintAt[k]},
                 {"pixel_share", pixels > 0 ? static_cast<double>(s.refine.pixelsAt[k]) /
                                                  static_cast<double>(pixels)
                                            : 0.0},
                 {"tiles", k == 0 ? 0 : s.refine.refined[k]}});
        }
        entry["refine"] = {{"tile_size", s.refine.tileSize},
                           {"tiles_seeing_surfaces", s.refine.tiles},
                           {"steps", share},
                           {"priority_threshold", s.refine.threshold},
                           {"gain_mse", s.refine.gainMse},
                           {"points", s.refine.shadingPoints},
                           {"seconds", s.refine.seconds},
                           {"pass_seconds", s.refine.passSeconds},
                           {"resolve_seconds", s.refine.resolveSeconds}};
        if (s.refine.estimatedPsnr >= 0.0)
            entry["refine"]["estimated_psnr"] = s.refine.estimatedPsnr;
    }
    addMultiphaseFrameJson(scene, s, entry);
    return entry;
}

nlohmann::json objectReportsJson(const MultiphaseRenderer& renderer) {
    nlohmann::json objects = nlohmann::json::array();
    for (size_t i = 0; i < renderer.objectCount(); ++i) {
        const ObjectReport& r = renderer.report(i);
        objects.push_back({{"name", r.name},
                           {"representation", representationName(renderer, i)},
                           {"reason", r.reason},
                           {"static_runs", r.staticRuns},
                           {"static_seconds", r.staticCosts.seconds},
                           {"frames_drawn", r.framesDrawn},
                           {"facets", r.facets},
                           {"longest_edge_pixels", r.longestEdgePixels},
                           {"facet_bytes", r.facetBytes},
                           {"resident_tiles", r.residentTiles},
                           {"tiles_filled", r.staticCosts.tilesFilled},
                           {"tiles_from_store", r.staticCosts.tilesLoaded},
                           {"map_bytes", r.mapBytes}});
        if (const std::string precision = mapPrecisionName(renderer, i); !precision.empty()) {
            objects.back()["map_precision"] = precision;
            if (const auto check = renderer.statics().precisionCheck(i))
                objects.back()["map_precision_check"] = {
                    {"reason", check->reason},
                    {"points", check->points},
                    {"largest_value", check->largestValue},
                    {"largest_change", std::isfinite(check->largestChange)
                                           ? nlohmann::json(check->largestChange)
                                           : nlohmann::json("inf")}};
        }
        // The direct rule's last priced frame (static_run_triggers.h): CPU ms by the model.
        const ObjectSlot& slot = renderer.slot(i);
        if (r.footprint.pixels > 0)
            objects.back()["footprint"] = {{"scale", r.footprintScale},
                                           {"pixels", r.footprint.pixels},
                                           {"noise", r.footprint.noise},
                                           {"scales_tried", r.footprint.scales},
                                           {"change", r.footprint.change}};
        if (slot.referenceMs > 0.0f)
            objects.back()["priced_ms_per_frame"] = {{"stored", slot.measuredMs},
                                                     {"reference", slot.referenceMs}};
    }
    return objects;
}

}  // namespace mpshade
