#include "app/eval_runner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>

#include <malloc.h>
#include <memory>
#include <string>

#include "app/eval_metrics.h"
#include "controller/multiphase_renderer.h"
#include "phases/image_compare.h"
#include "shadermaps/tile_store.h"

namespace mpshade {
namespace {

using Clock = std::chrono::steady_clock;

MultiphaseOptions multiphaseOptions(const EvalConfig& c) {
    MultiphaseOptions o;
    o.shadingRate = c.shadingRate;
    o.dynamic.footprintScale = c.footprintScale;
    o.dynamic.probe.filter = c.filter;
    o.dynamic.probe.maxAnisotropy = c.maxAnisotropy;
    o.dynamic.probe.levelAnisotropy = c.levelAnisotropy;
    o.staticPhase.combinedDicing.maxEdgePixels = c.facetEdgePixels;
    o.mapMemoryBytes = static_cast<size_t>(c.cacheMb) << 20;
    o.singlePhaseFrames = c.singlePhaseFrames;
    if (!c.storeFolder.empty()) o.staticPhase.store = std::make_shared<TileStore>(c.storeFolder);
    return o;
}

}  // namespace

namespace {
uint64_t statusBytes(const char* field) {
    std::ifstream in("/proc/self/status");
    std::string key;
    while (in >> key) {
        if (key == field) {
            uint64_t kb = 0;
            in >> kb;
            return kb << 10;
        }
        std::getline(in, key);
    }
    return 0;
}
}  // namespace

uint64_t currentResidentBytes() {
    return statusBytes("VmRSS:");
}
uint64_t peakResidentSinceReset() {
    return statusBytes("VmHWM:");
}

bool resetPeakResident() {
    // Memory earlier runs freed goes back to the system first, or it would hide this run's.
    ::malloc_trim(0);
    std::ofstream out("/proc/self/clear_refs");
    out << "5";
    out.flush();
    return static_cast<bool>(out);
}

EvalRun runEvalConfig(const std::string& scenePath, const EvalConfig& config, int first, int last,
                      const RenderOptions& base, const std::vector<Image>& truth,
                      const std::function<void()>& frameDone) {
    EvalRun run;
    run.config = config;
    Scene scene = loadScene(scenePath);
    if (config.rangeScale != 1.0f)
        for (SceneObject& o : scene.objects) {
            o.range.distanceFactor = 1.0f + (o.range.distanceFactor - 1.0f) * config.rangeScale;
            o.range.angle = std::min(180.0f, o.range.angle * config.rangeScale);
        }
    RenderOptions options = base;
    options.samplesPerPixel = config.spp;
    const bool peakKnown = resetPeakResident();
    const uint64_t residentBefore = currentResidentBytes();

    const auto start = Clock::now();
    std::unique_ptr<ReferenceRenderer> reference;
    std::unique_ptr<MultiphaseRenderer> multi;
    if (config.multiphase) {
        multi = std::make_unique<MultiphaseRenderer>(scene, multiphaseOptions(config));
        if (config.cutEveryFrame)
            multi->plan(first, first + 1, options);  // no frame after a cut is known
        else
            multi->plan(first, last, options);
    } else {
        reference = std::make_unique<ReferenceRenderer>(scene);
    }
    run.setupSeconds = secondsSince(start);

    Image previous;
    double mseSum = 0.0, temporalSum = 0.0;
    int temporalCount = 0;
    for (int f = first; f < last; ++f) {
        FrameStats stats;
        Image image;
        if (multi) {
            if (config.cutEveryFrame && f > first) {
                multi->discardStaticWork();
                multi->plan(f, f + 1, options);
            }
            image = multi->renderFrame(f, options, stats);
        } else {
            image = reference->renderFrame(f, options, stats);
        }
        const Image& t = truth[static_cast<size_t>(f - first)];
        EvalFrame e;
        e.index = f;
        e.wallSeconds = stats.wallSeconds;
        e.staticSeconds = stats.staticWork.seconds;
        const ImageError error = compareImages(image, t);
        e.rmse = error.rmse;
        e.mse = error.rmse * error.rmse;
        e.psnr = psnrOfMse(e.mse);
        e.maxAbs = error.maxAbs;
        e.nonFinite = stats.nonFiniteSamples;
        e.singlePhase = stats.singlePhase;
        run.singlePhaseFrames += e.singlePhase ? 1 : 0;
        if (f > first) {
            e.temporalRmse =
                temporalRmse(previous, image, truth[static_cast<size_t>(f - first - 1)], t);
            temporalSum += e.temporalRmse;
            ++temporalCount;
        }
        mseSum += e.mse;
        run.staticSeconds += e.staticSeconds;
        run.maxAbs = std::max(run.maxAbs, e.maxAbs);
        run.nonFinite += e.nonFinite;
        run.frames.push_back(e);
        previous = std::move(image);
        if (frameDone) frameDone();
    }
    run.sequenceSeconds = secondsSince(start);
    const double n = static_cast<double>(run.frames.size());
    double dynamic = 0.0;
    std::vector<double> steady;
    for (const EvalFrame& e : run.frames) {
        dynamic += std::max(0.0, e.wallSeconds - e.staticSeconds);
        if (e.index > first) steady.push_back(e.wallSeconds);
    }
    run.dynamicSecondsPerFrame = n > 0 ? dynamic / n : 0.0;
    if (steady.empty() && !run.frames.empty()) steady.push_back(run.frames[0].wallSeconds);
    if (!steady.empty()) {
        std::sort(steady.begin(), steady.end());
        run.steadyFrameSeconds = steady[steady.size() / 2];
    }
    const double mse = n > 0 ? mseSum / n : 0.0;
    run.psnr = psnrOfMse(mse);
    run.rmse = std::sqrt(mse);
    run.temporalRmse = temporalCount > 0 ? temporalSum / temporalCount : 0.0;
    const uint64_t peak = peakResidentSinceReset();
    run.peakMemoryMb = peakKnown && peak >= residentBefore
                           ? static_cast<double>(peak - residentBefore) / (1 << 20)
                           : -1.0;
    return run;
}

}  // namespace mpshade
