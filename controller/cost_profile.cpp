#include "controller/cost_profile.h"

#include <algorithm>
#include <chrono>
#include <cstdio>

#include <fmt/printf.h>

namespace mpshade {
namespace {

// printf-style into a string, checked against the arguments' types.
template <typename... Args>
std::string format(const char* f, const Args&... args) {
    return fmt::sprintf(f, args...);
}

double ms(double seconds) {
    return 1e3 * seconds;
}

double mb(uint64_t bytes) {
    return static_cast<double>(bytes) / (1024.0 * 1024.0);
}

}  // namespace

std::string representationName(const MultiphaseRenderer& renderer, size_t object) {
    const ObjectReport& r = renderer.report(object);
    if (r.kind == Representation::Auto) return "none (never seen)";
    if (r.kind == Representation::Direct) return "direct";
    if (renderer.factored(object).staticPart.channelOutputs.empty()) return "geometry";
    return r.kind == Representation::Facets ? "facets" : "shadermap";
}

std::string mapPrecisionName(const MultiphaseRenderer& renderer, size_t object) {
    const ObjectSlot& slot = renderer.slot(object);
    if (!slot.representation || !slot.representation->map) return "";
    return slot.representation->map->options().halfPrecision ? "half" : "float";
}

CostProfile profileScene(const Scene& scene, const std::string& scenePath,
                         const ProfileOptions& options, TraceRecorder& trace,
                         const std::function<void(int)>& progress) {
    const auto start = std::chrono::steady_clock::now();
    MultiphaseOptions mo = options.multiphase;
    mo.trace = &trace;
    MultiphaseRenderer renderer(scene, mo);
    renderer.plan(options.first, options.last, options.render);
    CostProfile p;
    p.scene = scenePath;
    p.first = options.first;
    p.last = options.last;
    p.singlePhaseFrames = mo.singlePhaseFrames;
    const size_t n = scene.objects.size();
    p.objects.resize(n);
    const int frames = std::max(0, options.last - options.first);
    for (ObjectProfile& o : p.objects) {
        o.staticSecondsPerFrame.assign(static_cast<size_t>(frames), 0.0);
        o.shadeSecondsPerFrame.assign(static_cast<size_t>(frames), 0.0);
    }
    // Reused frame to frame, as render and play reuse theirs: a new image each frame would
    // add its first touch (page faults) to the resolve's time.
    Image image;
    for (int frame = options.first; frame < options.last; ++frame) {
        FrameStats stats;
        renderer.renderFrame(frame, options.render, stats, image);
        const size_t k = static_cast<size_t>(frame - options.first);
        for (size_t i = 0; i < n; ++i) {
            ObjectProfile& o = p.objects[i];
            const ObjectSlot& slot = renderer.slot(i);
            o.staticSecondsPerFrame[k] = slot.frameStaticSeconds;
            o.shadeSecondsPerFrame[k] = slot.frameDynamic.shadeSeconds;
            o.shadingPoints += slot.frameDynamic.shadingPoints;
            o.dynamicInstructions += slot.frameDynamic.instructions;
        }
        p.frames.push_back(stats);
        if (progress) progress(frame);
    }
    for (size_t i = 0; i < n; ++i) {
        const ObjectReport& r = renderer.report(i);
        ObjectProfile& o = p.objects[i];
        o.name = r.name;
        o.representation = representationName(renderer, i);
        o.reason = r.reason;
        // A map's precision beside its representation, and what the auto check found.
        const std::string precision = mapPrecisionName(renderer, i);
        if (!precision.empty()) o.representation += " (" + precision + ")";
        if (const auto check = renderer.statics().precisionCheck(i); check && !precision.empty())
            o.reason += "; map precision " + check->reason;
        o.staticRuns = r.staticRuns;
        o.framesDrawn = r.framesDrawn;
        for (double s : o.staticSecondsPerFrame) o.staticSeconds += s;
        for (double s : o.shadeSecondsPerFrame) o.shadeSeconds += s;
        o.staticInstructions = r.staticCosts.instructions;
        o.tilesFilled = r.staticCosts.tilesFilled;
        o.residentTiles = r.residentTiles;
        o.pricedStoredMs = renderer.slot(i).measuredMs;
        o.pricedReferenceMs = renderer.slot(i).referenceMs;
        o.facets = r.facets;
        o.facetBytes = r.facetBytes;
        o.mapBytes = r.mapBytes;
    }
    const RenderOptions ro = options.render.resolved(scene.settings);
    p.width = ro.width;
    p.height = ro.height;
    p.spp = ro.samplesPerPixel;
    p.threads = trace.threads();
    p.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    p.machine = measureMachineLimits();
    p.stages = dynamicStageCosts(p.frames, p.spp, p.machine);
    return p;
}

namespace {

// The dynamic stages against the machine (stage_limits.h), with shade's parts.
std::string stagesMarkdown(const CostProfile& p) {
    std::string md;
    if (p.stages.empty()) return md;
    md += "## The dynamic phase against the machine\n\n";
    md += format(
        "Per sample per core: a stage's wall time times the %d cores sharing it, over the "
        "frame's samples (the median of the steady frames). The bound is the time the "
        "bytes the stage must stream take at the memory bandwidth measured now "
        "(%.1f GB/s, every core copying): a stage near it is memory-bound, one far above "
        "it computes (or waits on memory it does not stream). Shade's parts are CPU time "
        "summed over the threads, per sample; shade: other is what shade took beyond them "
        "(gathering points that waited for tiles, the last band, scheduling).\n\n",
        p.machine.cores, p.machine.bytesPerSecond / 1e9);
    md +=
        "| stage | ns per sample | bytes per sample | bound, ns | times the bound | "
        "dynamic instructions per sample |\n| --- | --- | --- | --- | --- | --- |\n";
    for (const StageCost& c : p.stages) {
        if (c.part) {
            md += format("| shade: %s | %.1f | | | | %s |\n", c.name.c_str(), c.nsPerSample,
                         c.instructionsPerSample > 0.0
                             ? format("%.0f", c.instructionsPerSample).c_str()
                             : "");
            continue;
        }
        md += format(
            "| %s | %.1f | %.0f | %.2f | %.1f | %s |\n", c.name.c_str(), c.nsPerSample,
            c.bytesPerSample, c.boundNsPerSample,
            c.boundNsPerSample > 0.0 ? c.nsPerSample / c.boundNsPerSample : 0.0,
            c.instructionsPerSample > 0.0 ? format("%.0f", c.instructionsPerSample).c_str() : "");
    }
    md += "\n";
    return md;
}

}  // namespace

std::string profileMarkdown(const CostProfile& p) {
    std::string md;
    md += "# mpshade profile: " + p.scene + "\n\n";
    md += format(
        "%dx%d, %d spp, frames %d:%d, multi-phase; %d threads reported work; %.3f s in "
        "all.\n\n",
        p.width, p.height, p.spp, p.first, p.last, p.threads, p.wallSeconds);
    if (!p.singlePhaseFrames)
        md +=
            "Every frame multi-phase (as `mpshade render --no-single-phase`): `render` may "
            "render a short request single-phase where its static work would not pay for "
            "itself.\n\n";
    md +=
        "A frame's phases are wall-clock milliseconds on the rendering thread. An object's "
        "static and shading milliseconds are summed over the threads that worked for it. "
        "`trace.json` has every span (open it in https://ui.perfetto.dev or chrome://tracing): "
        "a track per phase and one per thread.\n\n";

    double staticTotal = 0.0, dynamicTotal = 0.0, wallTotal = 0.0;
    int singlePhase = 0;
    for (const FrameStats& s : p.frames) {
        staticTotal += s.staticWork.seconds;
        dynamicTotal += s.dynamic.seconds();
        wallTotal += s.wallSeconds;
        singlePhase += s.singlePhase ? 1 : 0;
    }
    md += "## Static against dynamic\n\n";
    md += format("| | ms | share of the frames' time |\n| --- | --- | --- |\n");
    const double share = wallTotal > 0.0 ? 100.0 / wallTotal : 0.0;
    md += format(
        "| static phase (choosing representations, building, filling tiles) | %.1f | "
        "%.1f%% |\n",
        ms(staticTotal), staticTotal * share);
    md += format("| dynamic phase (warp, rasterize, shade, resolve) | %.1f | %.1f%% |\n",
                 ms(dynamicTotal), dynamicTotal * share);
    const double other = std::max(0.0, wallTotal - staticTotal - dynamicTotal);
    md += format(
        "| the rest (the sample layout at the first frame, buffers, bookkeeping) | %.1f | "
        "%.1f%% |\n",
        ms(other), other * share);
    md += format("| frames in all | %.1f | 100%% |\n\n", ms(wallTotal));
    if (singlePhase > 0)
        md += format(
            "%d frame(s) rendered single-phase (their static work would not have paid "
            "for itself); their time is in the total only.\n\n",
            singlePhase);

    md += stagesMarkdown(p);
    md += "## Per object\n\n";
    md +=
        "| object | representation | static runs | static ms | shading ms per frame drawn | "
        "shading points per frame | tiles filled | resident tiles | facets | static "
        "instructions | dynamic instructions per frame | memory MB |\n";
    md += "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
    for (const ObjectProfile& o : p.objects) {
        const double drawn = std::max(1, o.framesDrawn);
        md += format(
            "| %s | %s | %d | %.1f | %.2f | %.0f | %llu | %llu | %llu | %.3g | %.3g | "
            "%.2f |\n",
            o.name.c_str(), o.representation.c_str(), o.staticRuns, ms(o.staticSeconds),
            ms(o.shadeSeconds) / drawn, static_cast<double>(o.shadingPoints) / drawn,
            static_cast<unsigned long long>(o.tilesFilled),
            static_cast<unsigned long long>(o.residentTiles),
            static_cast<unsigned long long>(o.facets), static_cast<double>(o.staticInstructions),
            static_cast<double>(o.dynamicInstructions) / drawn, mb(o.facetBytes + o.mapBytes));
    }
    md += "\nWhy each representation:\n\n";
    for (const ObjectProfile& o : p.objects) {
        if (o.reason.empty()) continue;
        md += "- " + o.name + ": " + o.reason;
        if (o.pricedReferenceMs > 0.0 && o.representation != "direct")
            md += format(
                " (last priced frame: its stored representation's work %.1f ms of CPU, the "
                "reference's on the same samples %.1f ms)",
                o.pricedStoredMs, o.pricedReferenceMs);
        md += "\n";
    }

    md += "\n## Per frame\n\n";
    md +=
        "| frame | static ms | of it, fills | warp | rasterize | shade | resolve | frame ms | "
        "static runs | tiles filled | shaded points | resident MB |\n";
    md += "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
    for (const FrameStats& s : p.frames) {
        if (s.singlePhase) {
            md += format("| %d | single-phase | | | | | | %.1f | | | %llu | |\n", s.index,
                         ms(s.wallSeconds), static_cast<unsigned long long>(s.shadedPoints));
            continue;
        }
        md += format(
            "| %d | %.1f | %.1f | %.2f | %.2f | %.1f | %.2f | %.1f | %d | %llu | %llu | "
            "%.1f |\n",
            s.index, ms(s.staticWork.seconds), ms(s.staticWork.fillSeconds),
            ms(s.dynamic.warpSeconds), ms(s.dynamic.rasterSeconds), ms(s.dynamic.shadeSeconds),
            ms(s.dynamic.resolveSeconds), ms(s.wallSeconds), s.staticWork.work.runs,
            static_cast<unsigned long long>(s.staticWork.work.tilesFilled),
            static_cast<unsigned long long>(s.shadedPoints), mb(s.tiles.residentBytes));
    }
    return md;
}

}  // namespace mpshade
