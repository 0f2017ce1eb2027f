#include "app/render_command.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>

#include <fmt/format.h>
#include <unistd.h>
#include <nlohmann/json.hpp>

#include "app/command_line.h"
#include "app/frame_request.h"
#include "app/frame_stats_json.h"
#include "app/image_output.h"
#include "app/interrupt_watch.h"
#include "app/memory_limit.h"
#include "app/output_files.h"
#include "controller/cost_profile.h"
#include "controller/multiphase_renderer.h"
#include "geometry/error.h"
#include "phases/image_compare.h"
#include "phases/reference_renderer.h"
#include "scene/scene.h"
#include "shadermaps/tile_store.h"

namespace mpshade {
namespace {

class ProgressBar {
  public:
    explicit ProgressBar(bool enabled) : enabled_(enabled) {}
    void update(int frame, int frames, int done, int total) {
        if (!enabled_) return;
        std::lock_guard<std::mutex> lock(mutex_);
        const int width = 30;
        const int filled = total > 0 ? done * width / total : 0;
        const int percent = total > 0 ? done * 100 / total : 0;
        if (percent == lastPercent_ && frame == lastFrame_) return;
        lastPercent_ = percent;
        lastFrame_ = frame;
        std::fprintf(stderr, "\rframe %d (%d of %d) [%s%s] %3d%%", frame, frame - first_ + 1,
                     frames, std::string(static_cast<size_t>(filled), '#').c_str(),
                     std::string(static_cast<size_t>(width - filled), '.').c_str(), percent);
        std::fflush(stderr);
    }
    void setFirst(int first) { first_ = first; }
    void finish() {
        if (enabled_) std::fprintf(stderr, "\n");
    }

  private:
    bool enabled_;
    std::mutex mutex_;
    int lastPercent_ = -1, lastFrame_ = -1, first_ = 0;
};

// The options no scene is needed to check.
void checkRenderOptions(const RenderCommandOptions& options) {
    if (options.mode != "reference" && options.mode != "multiphase")
        throw InputError({"--mode", 0, 0, {}},
                         "unknown mode '" + options.mode + "' (available: reference, multiphase)");
    if (options.compare && options.mode != "multiphase")
        throw InputError({"--compare", 0, 0, {}},
                         "--compare measures --mode multiphase against the reference");
    if (options.truthSpp != -1 && !options.compare)
        throw InputError({"--truth-spp", 0, 0, {}}, "--truth-spp goes with --compare");
    if (options.truthSpp != -1 && (options.truthSpp < 1 || options.truthSpp > 1024))
        throw InputError({"--truth-spp", 0, 0, {}},
                         "expected 1..1024, found " + std::to_string(options.truthSpp));
    if (options.memoryMb < 0)
        throw InputError({"--memory-mb", 0, 0, {}}, "expected a positive number of MB");
    if (options.costImages && options.mode != "multiphase")
        throw InputError({"--cost-images", 0, 0, {}},
                         "--cost-images shows the multi-phase renderer's dynamic phase");
}

// The frame's shading cost images (--cost-images) and their sums in its stats entry.
// `noted`: whether a frame without one was reported already.
void writeCostImages(const MultiphaseRenderer& renderer, const Scene& scene, const std::string& dir,
                     int frame, nlohmann::json& entry, bool& noted) {
    const ShadingCostImage cost = renderer.lastFrameShadingCost();
    if (cost.width == 0) {
        entry["cost_image"] = nullptr;  // rendered single-phase: no dynamic phase to show
        if (!noted)
            std::fprintf(stderr,
                         "mpshade: note: frame %d was rendered single-phase, so it has no cost "
                         "image (--no-single-phase renders every frame multi-phase)\n",
                         frame);
        noted = true;
        return;
    }
    const std::string file = writeShadingCostImages(cost, dir, frame);
    nlohmann::json objects = nlohmann::json::object();
    for (size_t i = 0; i < cost.objectPoints.size() && i < scene.objects.size(); ++i)
        if (cost.objectPoints[i] > 0.0)
            objects[scene.objects[i].name] = {{"points", cost.objectPoints[i]},
                                              {"cost", cost.objectCost[i]}};
    entry["cost_image"] = {{"file", file},
                           {"points", cost.totalPoints()},
                           {"cost", cost.totalCost()},
                           {"objects", objects}};
}

// The multi-phase renderer's options from the command's.
MultiphaseOptions multiphaseOptions(const RenderCommandOptions& options) {
    MultiphaseOptions mo;
    if (!options.shadingRate.empty()) {
        if (options.shadingRate == "sample")
            mo.shadingRate = ShadingRate::Sample;
        else if (options.shadingRate == "pixel")
            mo.shadingRate = ShadingRate::Pixel;
        else if (options.shadingRate == "quad")
            mo.shadingRate = ShadingRate::Quad;
        else
            throw InputError({"--shading-rate", 0, 0, {}},
                             "expected sample, pixel or quad, found '" + options.shadingRate + "'");
    }
    if (options.footprintScale != 0.0f) {
        if (!(options.footprintScale >= 0.05f && options.footprintScale <= 8.0f))
            throw InputError({"--footprint-scale", 0, 0, {}},
                             "expected 0.05..8, found " + std::to_string(options.footprintScale));
        mo.dynamic.footprintScale = options.footprintScale;
    }
    if (options.footprints != "measured" && options.footprints != "uniform")
        throw InputError({"--footprints", 0, 0, {}},
                         "expected measured or uniform, found '" + options.footprints + "'");
    mo.footprints.enabled = options.footprints == "measured";
    if (options.cacheMb != 0) {
        if (options.cacheMb < 1 || options.cacheMb > (int64_t{1} << 20))
            throw InputError({"--cache-mb", 0, 0, {}},
                             "expected 1..1048576 MB, found " + std::to_string(options.cacheMb));
        mo.mapMemoryBytes = static_cast<size_t>(options.cacheMb) << 20;
    }
    if (options.viewLookahead < 0 || options.viewLookahead > 1000)
        throw InputError({"--view-lookahead", 0, 0, {}},
                         "expected 0..1000 frames, found " + std::to_string(options.viewLookahead));
    mo.viewLookahead = options.viewLookahead;
    // --compare measures the multi-phase engine against the reference: a frame the
    // reference rendered in its place would only be compared with itself.
    mo.singlePhaseFrames = !options.noSinglePhase && !options.compare;
    return mo;
}

// --compare: the frame against the reference's (and with --truth-spp both against a truth
// of many more samples: the error each makes, rather than how far apart they are), added
// to the frame's stats.json entry and reported.
// `ref` is the reference's image, reused frame to frame as the multi-phase one is (a fresh
// image's page faults would be timed as the reference's).
void compareFrame(int frame, const Image& image, const FrameStats& stats,
                  const RenderOptions& render, const RenderCommandOptions& options,
                  ReferenceRenderer& reference, Image& ref, nlohmann::json& entry) {
    FrameStats refStats;
    reference.renderFrame(frame, render, refStats, ref);
    const ImageError err = compareImages(image, ref);
    entry["reference"] = referenceFrameJson(stats, refStats, err);
    const char* newline = isatty(STDERR_FILENO) ? "\n" : "";
    if (options.truthSpp > 0) {
        RenderOptions dense = render;
        dense.samplesPerPixel = options.truthSpp;
        FrameStats truthStats;
        const Image truth = reference.renderFrame(frame, dense, truthStats);
        const ImageError m = compareImages(image, truth);
        const ImageError r = compareImages(ref, truth);
        entry["truth"] = {{"samples_per_pixel", options.truthSpp},
                          {"multiphase_psnr_db", m.psnr},
                          {"multiphase_rmse", m.rmse},
                          {"reference_psnr_db", r.psnr},
                          {"reference_rmse", r.rmse}};
        if (!options.quiet)
            std::fprintf(stderr,
                         "%sframe %d: against %d spp: multiphase %.2f dB, reference %.2f dB\n",
                         newline, frame, options.truthSpp, m.psnr, r.psnr);
    }
    if (!options.quiet)
        std::fprintf(stderr,
                     "%sframe %d: PSNR %.2f dB against the reference, %.3f s vs %.3f s (%.2fx)\n",
                     newline, frame, err.psnr, stats.wallSeconds, refStats.wallSeconds,
                     stats.wallSeconds > 0 ? refStats.wallSeconds / stats.wallSeconds : 0.0);
}

// --plan-frames A:B: the frames the renderer plans over (its representations, re-runs and
// single-phase frames), which must hold the request's [first, last); else the request's.
void planRange(const RenderCommandOptions& options, const Scene& scene, int first, int last,
               int& planFirst, int& planLast) {
    if (options.planFrames.empty()) return;
    if (options.mode != "multiphase")
        throw InputError({"--plan-frames", 0, 0, {}},
                         "--plan-frames plans the multi-phase renderer (the reference's frames are "
                         "independent)");
    try {
        parseFrameRange(options.planFrames, scene.frameCount(), planFirst, planLast, options.scene);
    } catch (const InputError& e) {
        throw InputError({"--plan-frames", 0, 0, {}}, e.message());  // not --frames
    }
    if (planFirst > first || planLast < last)
        throw InputError({"--plan-frames", 0, 0, {}},
                         fmt::format("must hold the frames asked for, {}:{}; found {}:{}", first,
                                     last, planFirst, planLast));
}

// Frames [from, to), rendered and not written: the state a render from `from` has at `to`
// (representations built and rebuilt, tiles resident), so the frames after are the bits a
// render from `from` gives (docs/store.md, "A farm").
void preroll(MultiphaseRenderer& renderer, const RenderOptions& render, int from, int to,
             bool quiet, Image& image) {
    for (int frame = from; frame < to; ++frame) {
        FrameStats stats;
        renderer.renderFrame(frame, render, stats, image);
        if (!quiet)
            std::fprintf(stderr,
                         "mpshade: frame %d rendered ahead of the request (%d of %d), "
                         "not written, %.3f s\n",
                         frame, frame - from + 1, to - from, stats.wallSeconds);
    }
}

}  // namespace

int runRenderCommand(const RenderCommandOptions& options) {
    checkRenderOptions(options);
    const bool multiphase = options.mode == "multiphase";
    FrameRequestOptions ask{options.scene, options.frames, options.size, options.spp, options.seed};
    ask.multiphase = multiphase;
    ask.reference = !multiphase || options.compare;
    ask.truthSpp = options.truthSpp;
    ask.memoryLimitBytes = static_cast<uint64_t>(options.memoryMb) << 20;
    const FrameRequest request = loadFrameRequest(ask);
    const Scene& scene = request.scene;
    const RenderOptions& render = request.render;
    const int first = request.first, last = request.last;
    prepareOutputFolder(options.outDir);

    const auto setupStart = std::chrono::steady_clock::now();
    std::unique_ptr<ReferenceRenderer> reference;
    if (ask.reference) reference = std::make_unique<ReferenceRenderer>(scene);
    std::unique_ptr<MultiphaseRenderer> multi;
    ShadingRate shadingRate = scene.settings.shadingRate;
    const std::shared_ptr<TileStore> store = multiphase ? openStore(options.run) : nullptr;
    if (multiphase) {
        MultiphaseOptions mo = multiphaseOptions(options);
        mo.staticPhase.store = store;
        shadingRate = mo.shadingRate.value_or(shadingRate);
        multi = std::make_unique<MultiphaseRenderer>(scene, mo);
    }
    int planFirst = first, planLast = last;
    planRange(options, scene, first, last, planFirst, planLast);
    if (multi) multi->plan(planFirst, planLast, render);
    const double setupSeconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - setupStart).count();
    Renderer& renderer = multiphase ? static_cast<Renderer&>(*multi) : *reference;
    ProgressBar bar(!options.quiet && isatty(STDERR_FILENO));
    bar.setFirst(first);
    nlohmann::json frames = nlohmann::json::array();
    const auto start = std::chrono::steady_clock::now();
    // stats.json, rewritten (atomically) after every frame: what a stopped render
    // finished is always described. A shard's is its own (stats_A_B.json), so shards
    // rendering into one folder never overwrite one another's.
    const std::string statsName =
        options.shardStats ? fmt::format("stats_{:04d}_{:04d}.json", first, last) : "stats.json";
    const auto writeStats = [&] {
        nlohmann::json doc = {
            {"scene", options.scene},
            {"mode", options.mode},
            {"width", request.resolved.width},
            {"height", request.resolved.height},
            {"samples_per_pixel", request.resolved.samplesPerPixel},
            {"seed", options.seed},
            {"frames_requested", last - first},
            {"memory_limit_mb", request.memoryLimitBytes >> 20},
            {"peak_resident_mb", peakResidentBytes() >> 20},
            {"setup_seconds", setupSeconds},
            {"total_wall_seconds",
             std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()},
            {"frames", frames}};
        if (multi) {
            doc["shading_rate"] = shadingRateName(shadingRate);
            doc["objects"] = objectReportsJson(*multi);
            doc["store"] = storeReport(store);
        }
        writeTextFile(std::filesystem::path(options.outDir) / statsName, doc.dump(2) + "\n");
    };
    const InterruptWatch watch;
    Image image, referenceImage;  // reused frame to frame
    if (multi) preroll(*multi, render, planFirst, first, options.quiet, image);
    // Without a terminal (a farm's log), a line a frame instead of the bar.
    const bool lines = !options.quiet && !isatty(STDERR_FILENO);
    int skipped = 0;
    bool notedNoCostImage = false;
    for (int frame = first; frame < last; ++frame) {
        if (options.skipExisting && frameImagesExist(options.outDir, frame)) {
            ++skipped;
            // Planned from an earlier frame, the frames after it need its state: rendered
            // again, not written.
            if (multi && !options.planFrames.empty())
                preroll(*multi, render, frame, frame + 1, true, image);
            continue;
        }
        FrameStats stats;
        renderer.renderFrame(frame, render, stats, image, [&](int done, int total) {
            bar.update(frame, last - first, done, total);
        });
        writeFrameImages(image, options.outDir, frame);
        nlohmann::json entry = renderFrameJson(scene, stats, multiphase, image);
        if (options.costImages)
            writeCostImages(*multi, scene, options.outDir, frame, entry, notedNoCostImage);
        if (options.compare)
            compareFrame(frame, image, stats, render, options, *reference, referenceImage, entry);
        frames.push_back(entry);
        writeStats();
        if (lines)
            std::fprintf(stderr, "mpshade: frame %d done (%d of %d) in %.3f s\n", frame,
                         frame - first + 1, last - first, stats.wallSeconds);
        if (interrupted()) break;
    }
    if (skipped > 0 && !options.quiet)
        std::fprintf(stderr, "mpshade: %d frame(s) already in %s were not written again\n", skipped,
                     options.outDir.c_str());
    bar.finish();
    cleanUpStore(store, options.run, scene);
    if (interrupted()) {
        std::fprintf(stderr,
                     "mpshade: stopped by the user after %zu frame(s); stats.json "
                     "describes them\n",
                     frames.size());
        return 130;
    }
    return 0;
}

}  // namespace mpshade
