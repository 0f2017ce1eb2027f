#include "app/play_command.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <utility>

#include <unistd.h>
#include <nlohmann/json.hpp>

#include "app/frame_request.h"
#include "app/frame_stats_json.h"
#include "app/image_output.h"
#include "app/interrupt_watch.h"
#include "app/memory_limit.h"
#include "app/output_files.h"
#include "controller/playback.h"
#include "geometry/error.h"
#include "scene/scene.h"

namespace mpshade {

int runPlayCommand(const PlayCommandOptions& options) {
    if (!(options.fps >= 0.1 && options.fps <= 1000.0))
        throw InputError({"--fps", 0, 0, {}}, "expected 0.1..1000 frames per second, found " +
                                                  std::to_string(options.fps));
    if (options.cacheMb < 1 || options.cacheMb > (int64_t{1} << 20))
        throw InputError({"--cache-mb", 0, 0, {}},
                         "expected 1..1048576 MB, found " + std::to_string(options.cacheMb));
    const FrameRequest request =
        loadFrameRequest({options.scene, options.frames, options.size, options.spp, options.seed});
    const Scene& scene = request.scene;
    const int width = request.width, height = request.height, spp = request.spp;
    PlaybackOptions po;
    po.fps = options.fps;
    po.render = request.render;
    po.first = request.first;
    po.last = request.last;
    po.cacheBytes = static_cast<size_t>(options.cacheMb) << 20;
    po.prefetch = !options.noPrefetch;
    po.backgroundFills = !options.noBackgroundFills;
    prepareOutputFolder(options.outDir);
    const std::filesystem::path dir(options.outDir);
    const bool tty = !options.quiet && isatty(STDERR_FILENO);

    nlohmann::json frames = nlohmann::json::array();
    int met = 0;
    double preroll = 0.0;
    // stats.json, rewritten (atomically) after every frame: what a stopped playback
    // finished is always described.
    const auto writeStats = [&](double prerollSeconds) {
        const int played = static_cast<int>(frames.size());
        const nlohmann::json doc = {
            {"scene", options.scene},
            {"mode", "play"},
            {"fps", options.fps},
            {"width", width},
            {"height", height},
            {"samples_per_pixel", spp},
            {"seed", options.seed},
            {"cache_mb", options.cacheMb},
            {"prefetch", !options.noPrefetch},
            {"background_fills", !options.noBackgroundFills},
            {"preroll_seconds", prerollSeconds},
            {"frames_requested", po.last - po.first},
            {"frames_played", played},
            {"deadlines_met", met},
            {"deadline_met_fraction", played > 0 ? static_cast<double>(met) / played : 1.0},
            {"peak_resident_mb", peakResidentBytes() >> 20},
            {"frames", frames}};
        writeTextFile(dir / "stats.json", doc.dump(2) + "\n");
    };
    const InterruptWatch watch;
    const auto onFrame = [&](const FrameStats& s, const Image& image,
                             const PlaybackQuality& quality) {
        double writeSeconds = 0.0;
        if (!options.noWrite) {
            const auto began = std::chrono::steady_clock::now();
            writeFrameImages(image, dir.string(), s.index);
            writeSeconds =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
        }
        met += s.deadlineMet ? 1 : 0;
        nlohmann::json entry = {
            {"index", s.index},
            {"time", s.time},
            {"wall_seconds", s.wallSeconds},
            {"budget_seconds", s.budgetSeconds},
            {"deadline_met", s.deadlineMet},
            {"write_seconds", writeSeconds},
            {"built_ahead", s.builtAhead},
            {"quality",
             {{"level", quality.level},
              {"shading_rate", shadingRateName(quality.step.rate)},
              {"footprint_scale", quality.step.footprintScale},
              {"samples_per_pixel",
               quality.step.samplesPerPixel > 0 ? quality.step.samplesPerPixel : spp},
              {"probes", s.probes},
              {"probe_fallbacks", s.probeFallbacks},
              {"older_representations", s.rebuildsDeferred}}},
            {"deferred", {{"tiles", s.tilesDeferred}, {"rebuilds", s.rebuildsDeferred}}},
            {"probe_hits", s.probes - s.probeFallbacks},
            {"controller_seconds", s.controllerSeconds},
            {"prefetch",
             {{"predicted", s.tilesPredicted},
              {"abandoned", s.predictionAbandoned},
              {"adjacent", s.tilesAdjacent},
              {"filled", s.tilesPrefetched},
              {"used", s.prefetchUsed},
              {"wasted", s.prefetchWasted},
              {"seconds", s.prefetchSeconds}}},
            {"background",
             {{"filled", s.backgroundTilesFilled},
              {"evicted", s.backgroundTilesEvicted},
              {"seconds", s.backgroundSeconds}}},
            {"shaded_points", s.shadedPoints}};
        addMultiphaseFrameJson(scene, s, entry);
        frames.push_back(std::move(entry));
        if (tty)
            std::fprintf(stderr, "\rframe %d: %.1f ms of %.1f, %d of %zu on time", s.index,
                         1e3 * s.wallSeconds, 1e3 * s.budgetSeconds, met, frames.size());
        writeStats(preroll);
        return !interrupted();
    };
    const PlaybackSummary summary =
        playScene(scene, po, onFrame, [&](double seconds) { preroll = seconds; });
    if (tty) std::fprintf(stderr, "\n");
    writeStats(summary.prerollSeconds);
    if (interrupted()) {
        std::fprintf(stderr,
                     "mpshade: stopped by the user after %zu frame(s); stats.json "
                     "describes them\n",
                     frames.size());
        return 130;
    }
    if (!options.quiet)
        std::fprintf(stderr,
                     "mpshade: %d of %d frame(s) within 1/%g s (%.1f%%), after a %.2f s "
                     "pre-roll; stats in %s\n",
                     summary.deadlinesMet, summary.frames, options.fps,
                     summary.frames > 0 ? 100.0 * summary.deadlinesMet / summary.frames : 100.0,
                     summary.prerollSeconds, (dir / "stats.json").string().c_str());
    return 0;
}

}  // namespace mpshade
