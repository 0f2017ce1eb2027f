#include "app/play_command.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <unistd.h>
#include <nlohmann/json.hpp>

#include "app/frame_request.h"
#include "app/frame_stats_json.h"
#include "app/image_output.h"
#include "app/interrupt_watch.h"
#include "app/memory_limit.h"
#include "app/output_files.h"
#include "app/played_quality.h"
#include "controller/playback.h"
#include "geometry/error.h"
#include "scene/scene.h"

namespace mpshade {
namespace {

// "per pixel, footprint x2, 2 spp": a step as the summary names it.
std::string describeStep(const QualityStep& step, int spp) {
    std::string s = step.rate == ShadingRate::Sample  ? "per sample"
                    : step.rate == ShadingRate::Pixel ? "per pixel"
                                                      : "per 2x2 pixels";
    if (step.footprintScale != 1.0f) {
        char scale[32];
        std::snprintf(scale, sizeof scale, ", footprint x%g", step.footprintScale);
        s += scale;
    }
    return s + ", " + std::to_string(step.samplesPerPixel > 0 ? step.samplesPerPixel : spp) +
           " spp";
}

double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
    std::nth_element(v.begin(), mid, v.end());
    return *mid;
}

// Where the frames' time went, and what each quality step costs: why the frames played at
// the quality they did.
void printPlaySummary(const std::vector<PlaybackStep>& steps, const std::vector<FrameStats>& played,
                      int spp, double fps, const PlayedQuality* quality) {
    std::fprintf(stderr,
                 "  steps, best first: the first frame's dynamic phase at each (measured in "
                 "the pre-roll; the slot is %.1f ms), and the frames played there\n",
                 1e3 / fps);
    for (const PlaybackStep& p : steps) {
        const std::string name = describeStep(p.step, spp);
        // A step measured with probes falling back (a cache too small for its tiles) is
        // priced high: the fallback path is slower.
        const std::string fell =
            p.probeFallbacks > 0 ? fmt::format("  ({} probes fell back)",
                                               static_cast<unsigned long long>(p.probeFallbacks))
                                 : std::string();
        if (p.frames > 0)
            std::fprintf(stderr, "    %-34s %7.1f ms  %d frame(s)%s\n", name.c_str(),
                         1e3 * p.dynamicSeconds, p.frames, fell.c_str());
        else
            std::fprintf(stderr, "    %-34s %7.1f ms%s\n", name.c_str(), 1e3 * p.dynamicSeconds,
                         fell.c_str());
    }
    auto med = [&](auto field) {
        std::vector<double> v;
        for (const FrameStats& s : played) v.push_back(1e3 * field(s));
        return median(std::move(v));
    };
    std::fprintf(stderr,
                 "  median frame: %.1f ms; dynamic phase %.1f (rasterize %.1f, shade %.1f, resolve "
                 "%.1f), static %.1f, controller %.2f\n",
                 med([](const FrameStats& s) { return s.wallSeconds; }),
                 med([](const FrameStats& s) { return s.dynamic.seconds(); }),
                 med([](const FrameStats& s) { return s.dynamic.rasterSeconds; }),
                 med([](const FrameStats& s) { return s.dynamic.shadeSeconds; }),
                 med([](const FrameStats& s) { return s.dynamic.resolveSeconds; }),
                 med([](const FrameStats& s) { return s.staticWork.seconds; }),
                 med([](const FrameStats& s) { return s.controllerSeconds; }));
    DynamicFrameStats dynamic;
    PrefetchStats prefetch;
    for (const FrameStats& s : played) {
        dynamic += s.dynamic;
        prefetch += s.prefetch;
    }
    // Read and wasted count the pre-roll's prefetched tiles too.
    std::fprintf(stderr,
                 "  probes answered from a coarser level: %.2f%%; tiles prefetched while "
                 "playing %llu; of all prefetched (the pre-roll's too), read by a later "
                 "frame %llu, wasted %llu\n",
                 dynamic.probes > 0 ? 100.0 * static_cast<double>(dynamic.probeFallbacks) /
                                          static_cast<double>(dynamic.probes)
                                    : 0.0,
                 static_cast<unsigned long long>(prefetch.filled),
                 static_cast<unsigned long long>(prefetch.used),
                 static_cast<unsigned long long>(prefetch.wasted));
    BackgroundStats background;
    int builtInFrames = 0;
    for (const FrameStats& s : played) {
        background += s.background;
        builtInFrames += s.staticWork.work.runs;
    }
    std::fprintf(stderr,
                 "  static runs within frames %d; rebuilt on the background worker %d (%.1f ms "
                 "of its CPU); tiles it filled %llu\n",
                 builtInFrames, background.rebuilds, 1e3 * background.rebuildSeconds,
                 static_cast<unsigned long long>(background.tilesFilled));
    std::vector<double> refined, estimated, refineMs;
    for (const FrameStats& s : played) {
        if (!s.refine.ran) continue;
        uint64_t all = 0;
        for (int k = 0; k < s.refine.steps; ++k) all += s.refine.pixelsAt[k];
        refined.push_back(all > 0 ? 100.0 * static_cast<double>(all - s.refine.pixelsAt[0]) /
                                        static_cast<double>(all)
                                  : 0.0);
        if (s.refine.estimatedPsnr >= 0.0) estimated.push_back(s.refine.estimatedPsnr);
        refineMs.push_back(1e3 * s.refine.seconds);
    }
    if (!refined.empty()) {
        std::fprintf(stderr,
                     "  refinement (%zu of %zu frames): median %.0f%% of pixels shaded again at "
                     "a better step, in %.1f ms",
                     refined.size(), played.size(), median(refined), median(refineMs));
        if (!estimated.empty())
            std::fprintf(stderr, "; estimated %.1f dB from constant quality", median(estimated));
        std::fprintf(stderr, "\n");
    }
    if (quality && !quality->frames().empty()) {
        std::vector<double> psnr, temporal;
        int good = 0;
        for (const PlayedFrameQuality& q : quality->frames()) {
            psnr.push_back(q.psnr);
            good += q.psnr >= 38.0 ? 1 : 0;
            if (q.temporalRmse >= 0.0) temporal.push_back(q.temporalRmse);
        }
        const double least = *std::min_element(psnr.begin(), psnr.end());
        std::fprintf(stderr,
                     "  against the constant-quality frames: median %.2f dB (least %.2f), %d of "
                     "%zu at 38 dB or more; temporal RMSE median %.5f\n",
                     median(psnr), least, good, psnr.size(), median(temporal));
    }
}

// The options checked, and playback's options from them and the request.
PlaybackOptions playbackOptions(const PlayCommandOptions& options, const FrameRequest& request) {
    if (!(options.fps >= 0.1 && options.fps <= 1000.0))
        throw InputError({"--fps", 0, 0, {}}, "expected 0.1..1000 frames per second, found " +
                                                  std::to_string(options.fps));
    if (options.cacheMb < 1 || options.cacheMb > (int64_t{1} << 20))
        throw InputError({"--cache-mb", 0, 0, {}},
                         "expected 1..1048576 MB, found " + std::to_string(options.cacheMb));
    if (options.refine != "on" && options.refine != "off")
        throw InputError({"--refine", 0, 0, {}},
                         "expected 'on' or 'off', found '" + options.refine + "'");
    if (options.footprints != "measured" && options.footprints != "uniform")
        throw InputError({"--footprints", 0, 0, {}},
                         "expected measured or uniform, found '" + options.footprints + "'");
    if (options.refineTile < 4 || options.refineTile > 256 || options.refineTile % 2 != 0)
        throw InputError({"--refine-tile", 0, 0, {}},
                         "expected an even number of pixels 4..256, found " +
                             std::to_string(options.refineTile));
    PlaybackOptions po;
    po.fps = options.fps;
    po.render = request.render;
    po.first = request.first;
    po.last = request.last;
    po.cacheBytes = static_cast<size_t>(options.cacheMb) << 20;
    po.prefetch = !options.noPrefetch;
    po.backgroundFills = !options.noBackgroundFills;
    po.backgroundRebuilds = !options.noBackgroundRebuilds;
    po.refine.enabled = options.refine == "on";
    po.refine.tileSize = options.refineTile;
    po.footprints.enabled = options.footprints == "measured";
    return po;
}

}  // namespace

int runPlayCommand(const PlayCommandOptions& options) {
    const FrameRequest request =
        loadFrameRequest({options.scene, options.frames, options.size, options.spp, options.seed});
    PlaybackOptions po = playbackOptions(options, request);
    po.store = openStore(options.run);
    const Scene& scene = request.scene;
    const int width = request.resolved.width, height = request.resolved.height,
              spp = request.resolved.samplesPerPixel;
    std::unique_ptr<PlayedQuality> measured;
    if (!options.compareTo.empty()) measured = std::make_unique<PlayedQuality>(options.compareTo);
    prepareOutputFolder(options.outDir);
    const std::filesystem::path dir(options.outDir);
    const bool tty = !options.quiet && isatty(STDERR_FILENO);

    nlohmann::json frames = nlohmann::json::array();
    int met = 0;
    double preroll = 0.0;
    std::vector<PlaybackStep> steps;  // frames counted here as they are played
    std::vector<FrameStats> playedFrames;
    // Object name to the footprint multiplier the pre-roll measured (empty: none measured).
    nlohmann::json footprints = nlohmann::json::object();
    // stats.json, rewritten (atomically) after every frame: what a stopped playback
    // finished is always described.
    const auto writeStats = [&](double prerollSeconds) {
        const int played = static_cast<int>(frames.size());
        nlohmann::json ladder = nlohmann::json::array();
        for (size_t k = 0; k < steps.size(); ++k) {
            const QualityStep& q = steps[k].step;
            ladder.push_back(
                {{"level", k},
                 {"shading_rate", shadingRateName(q.rate)},
                 {"footprint_scale", q.footprintScale},
                 {"samples_per_pixel", q.samplesPerPixel > 0 ? q.samplesPerPixel : spp},
                 {"preroll_dynamic_seconds", steps[k].dynamicSeconds},
                 {"preroll_measured_seconds", steps[k].measuredSeconds},
                 {"preroll_probe_fallbacks", steps[k].probeFallbacks},
                 {"frames", steps[k].frames}});
        }
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
            {"background_rebuilds", !options.noBackgroundRebuilds},
            {"preroll_seconds", prerollSeconds},
            {"frames_requested", po.last - po.first},
            {"frames_played", played},
            {"deadlines_met", met},
            {"deadline_met_fraction", played > 0 ? static_cast<double>(met) / played : 1.0},
            {"peak_resident_mb", peakResidentBytes() >> 20},
            {"steps", ladder},
            {"object_footprints", footprints},
            {"store", storeReport(po.store)},
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
        met += s.budget.deadlineMet ? 1 : 0;
        if (static_cast<size_t>(quality.level) < steps.size())
            ++steps[static_cast<size_t>(quality.level)].frames;
        playedFrames.push_back(s);
        nlohmann::json entry = playFrameJson(scene, s, quality, spp, writeSeconds);
        if (measured) {
            const PlayedFrameQuality q = measured->measure(image, s.index);
            entry["constant_quality"] = {{"psnr", q.psnr}};
            if (q.temporalRmse >= 0.0) entry["constant_quality"]["temporal_rmse"] = q.temporalRmse;
        }
        frames.push_back(std::move(entry));
        if (tty)
            std::fprintf(stderr, "\rframe %d: %.1f ms of %.1f, %d of %zu on time", s.index,
                         1e3 * s.wallSeconds, 1e3 * s.budget.seconds, met, frames.size());
        writeStats(preroll);
        return !interrupted();
    };
    const PlaybackSummary summary = playScene(scene, po, onFrame, [&](const PlaybackSummary& s) {
        preroll = s.prerollSeconds;
        steps = s.steps;
        for (size_t i = 0; i < s.objectFootprints.size(); ++i)
            footprints[scene.objects[i].name] = s.objectFootprints[i];
    });
    if (tty) std::fprintf(stderr, "\n");
    cleanUpStore(po.store, options.run, scene);
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
    if (!options.quiet && !playedFrames.empty())
        printPlaySummary(summary.steps, playedFrames, spp, options.fps, measured.get());
    return 0;
}

}  // namespace mpshade
