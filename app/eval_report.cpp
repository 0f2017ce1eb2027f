#include "app/eval_report.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "app/output_files.h"

namespace mpshade {
namespace {

// JSON has no infinity: an exact match is written as the string "inf".
nlohmann::json number(double x) {
    if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
    if (std::isnan(x)) return nullptr;
    return x;
}

std::vector<TimedError> points(const SceneEvaluation& e, bool multiphase, bool steady) {
    std::vector<TimedError> p(e.runs.size());
    for (size_t i = 0; i < e.runs.size(); ++i) {
        const EvalRun& r = e.runs[i];
        p[i].psnr = r.psnr;
        p[i].seconds = r.config.multiphase != multiphase ? INFINITY
                       : steady                          ? r.steadyFrameSeconds
                                                         : r.sequenceSeconds;
    }
    return p;
}

EqualErrorSpeedup speedupOf(const SceneEvaluation& e, size_t run) {
    EqualErrorSpeedup s;
    const EvalRun& r = e.runs[run];
    s.label = r.config.label;
    s.psnr = r.psnr;
    const LadderTime whole = timeAtPsnr(points(e, false, false), r.psnr);
    const LadderTime steady = timeAtPsnr(points(e, false, true), r.psnr);
    if (!whole.valid || r.sequenceSeconds <= 0.0) return s;
    s.valid = true;
    s.sequence = whole.seconds / r.sequenceSeconds;
    s.steady = r.steadyFrameSeconds > 0.0 ? steady.seconds / r.steadyFrameSeconds : 0.0;
    s.extrapolated = whole.extrapolated;
    return s;
}

nlohmann::json speedupJson(const EqualErrorSpeedup& s) {
    if (!s.valid) return nullptr;
    return {{"config", s.label},
            {"psnr_db", number(s.psnr)},
            {"sequence", s.sequence},
            {"steady_state", s.steady},
            {"extrapolated", s.extrapolated}};
}

const char* filterName(ProbeFilter f) {
    return f == ProbeFilter::Trilinear ? "trilinear" : f == ProbeFilter::EWA ? "ewa" : "feline";
}

nlohmann::json runJson(const EvalRun& r, const SceneEvaluation& e) {
    const EvalConfig& c = r.config;
    nlohmann::json settings = {{"samples_per_pixel", c.spp > 0 ? c.spp : e.spp}};
    if (c.multiphase) {
        settings["shading_rate"] = shadingRateName(c.shadingRate);
        settings["footprint_scale"] = c.footprintScale;
        settings["probe_filter"] = filterName(c.filter);
        settings["max_anisotropy"] = c.maxAnisotropy;
        settings["level_anisotropy"] = c.levelAnisotropy;
        settings["facet_edge_pixels"] = c.facetEdgePixels;
        settings["range_scale"] = c.rangeScale;
        settings["cache_mb"] = c.cacheMb;
        settings["cut_every_frame"] = c.cutEveryFrame;
        settings["single_phase_frames"] = c.singlePhaseFrames;
        settings["store"] = !c.storeFolder.empty();
    }
    nlohmann::json frames = nlohmann::json::array();
    for (const EvalFrame& f : r.frames)
        frames.push_back({{"index", f.index},
                          {"wall_seconds", f.wallSeconds},
                          {"static_seconds", f.staticSeconds},
                          {"psnr_db", number(f.psnr)},
                          {"rmse", f.rmse},
                          {"max_abs_error", f.maxAbs},
                          {"temporal_rmse", f.temporalRmse >= 0.0 ? nlohmann::json(f.temporalRmse)
                                                                  : nlohmann::json(nullptr)},
                          {"nonfinite_samples", f.nonFinite},
                          {"single_phase", f.singlePhase}});
    return {{"label", c.label},
            {"mode", c.multiphase ? "multiphase" : "reference"},
            {"knob", c.knob},
            {"settings", settings},
            {"setup_seconds", r.setupSeconds},
            {"sequence_seconds", r.sequenceSeconds},
            {"static_seconds", r.staticSeconds},
            {"dynamic_seconds_per_frame", r.dynamicSecondsPerFrame},
            {"steady_frame_seconds", r.steadyFrameSeconds},
            {"peak_memory_mb", r.peakMemoryMb},
            {"psnr_db", number(r.psnr)},
            {"rmse", r.rmse},
            {"max_abs_error", r.maxAbs},
            {"temporal_rmse", r.temporalRmse},
            {"nonfinite_samples", r.nonFinite},
            {"single_phase_frames", r.singlePhaseFrames},
            {"frames", frames}};
}

std::string fmt(const char* format, double x) {
    char buf[64];
    std::snprintf(buf, sizeof buf, format, x);
    return buf;
}

std::string psnrText(double x) {
    return std::isinf(x) ? "inf" : fmt("%.2f", x);
}

std::string speedupText(const EqualErrorSpeedup& s) {
    if (!s.valid) return "n/a";
    return fmt("%.2fx", s.sequence) + " (steady frames " + fmt("%.2fx", s.steady) + ")" +
           (s.extrapolated ? ", extrapolated beyond the reference's ladder" : "");
}

bool haveGnuplot() {
    return std::system("command -v gnuplot >/dev/null 2>&1") == 0;
}

}  // namespace

void summarize(SceneEvaluation& e) {
    e.referenceFront.clear();
    e.multiphaseFront.clear();
    for (bool mp : {false, true}) {
        const std::vector<size_t> front = paretoFront(points(e, mp, false));
        (mp ? e.multiphaseFront : e.referenceFront) = front;
    }
    e.atDefault = speedupOf(e, e.defaultRun);
    e.best = {};
    for (size_t i = 0; i < e.runs.size(); ++i) {
        if (!e.runs[i].config.multiphase) continue;
        const EqualErrorSpeedup s = speedupOf(e, i);
        // Only settings within the reference ladder count for the best: an extrapolated
        // ratio is an estimate.
        if (s.valid && !s.extrapolated && (!e.best.valid || s.sequence > e.best.sequence))
            e.best = s;
    }
    // At the error the reference makes at the scene's own samples: multi-phase's front
    // interpolated to that PSNR.
    e.atReferencePsnr = {};
    const EvalRun& ref = e.runs[e.referenceAtSpp];
    const LadderTime mpWhole = timeAtPsnr(points(e, true, false), ref.psnr);
    const LadderTime mpSteady = timeAtPsnr(points(e, true, true), ref.psnr);
    if (mpWhole.valid && mpWhole.seconds > 0.0) {
        e.atReferencePsnr.valid = true;
        e.atReferencePsnr.label = "multi-phase front at " + ref.config.label + "'s PSNR";
        e.atReferencePsnr.psnr = ref.psnr;
        e.atReferencePsnr.sequence = ref.sequenceSeconds / mpWhole.seconds;
        e.atReferencePsnr.steady =
            mpSteady.seconds > 0.0 ? ref.steadyFrameSeconds / mpSteady.seconds : 0.0;
        e.atReferencePsnr.extrapolated = mpWhole.extrapolated;
    }
    e.worstCaseOverhead =
        ref.sequenceSeconds > 0.0 ? e.worstCase.sequenceSeconds / ref.sequenceSeconds - 1.0 : 0.0;
    // The warm store renders the defaults' images (a stored tile holds what filling it
    // gives), so its speedup at equal PSNR is the defaults' scaled by the time it saves.
    const EvalRun& def = e.runs[e.defaultRun];
    e.warmStoreSpeedup =
        e.atDefault.valid && e.warmStore.sequenceSeconds > 0.0
            ? e.atDefault.sequence * def.sequenceSeconds / e.warmStore.sequenceSeconds
            : 0.0;
    e.warmStoreGain = e.atDefault.valid && e.atDefault.sequence > 0.0
                          ? e.warmStoreSpeedup / e.atDefault.sequence
                          : 0.0;
}

nlohmann::json toJson(const SceneEvaluation& e) {
    nlohmann::json runs = nlohmann::json::array();
    for (const EvalRun& r : e.runs) runs.push_back(runJson(r, e));
    auto labels = [&](const std::vector<size_t>& front) {
        nlohmann::json out = nlohmann::json::array();
        for (size_t i : front)
            out.push_back({{"config", e.runs[i].config.label},
                           {"sequence_seconds", e.runs[i].sequenceSeconds},
                           {"psnr_db", number(e.runs[i].psnr)}});
        return out;
    };
    const EvalRun& ref = e.runs[e.referenceAtSpp];
    return {{"scene", e.scene},
            {"name", e.name},
            {"width", e.width},
            {"height", e.height},
            {"samples_per_pixel", e.spp},
            {"frames", {e.first, e.last}},
            {"truth",
             {{"samples_per_pixel", e.truthSpp},
              {"frames_cached", e.truthFramesCached},
              {"frames_rendered", e.truthFramesRendered},
              {"seconds", e.truthSeconds},
              {"self_psnr_db", number(e.truthSelfPsnr)}}},
            {"configs", runs},
            {"pareto",
             {{"reference", labels(e.referenceFront)}, {"multiphase", labels(e.multiphaseFront)}}},
            {"speedup_at_equal_psnr",
             {{"default", speedupJson(e.atDefault)},
              {"best", speedupJson(e.best)},
              {"at_reference_psnr", speedupJson(e.atReferencePsnr)}}},
            {"worst_case_overhead",
             {{"overhead", e.worstCaseOverhead},
              {"cut_every_frame", runJson(e.worstCase, e)},
              {"reference_config", ref.config.label},
              {"reference_sequence_seconds", ref.sequenceSeconds}}},
            {"store",
             {{"cold", runJson(e.coldStore, e)},
              {"warm", runJson(e.warmStore, e)},
              {"warm_speedup_at_equal_psnr", e.warmStoreSpeedup},
              {"warm_over_default", e.warmStoreGain}}}};
}

std::vector<std::string> writePlots(const SceneEvaluation& e, const std::filesystem::path& dir) {
    if (!haveGnuplot()) {
        std::fprintf(stderr, "mpshade eval: gnuplot is not installed: no plots for %s\n",
                     e.name.c_str());
        return {};
    }
    const std::filesystem::path folder = dir / e.name;
    std::filesystem::create_directories(folder);
    const double frames = std::max(1, e.last - e.first);
    // Data: one block per mode (every configuration), then one per front.
    std::ostringstream data;
    for (bool mp : {false, true}) {
        for (const EvalRun& r : e.runs)
            if (r.config.multiphase == mp && std::isfinite(r.psnr))
                data << r.sequenceSeconds / frames << ' ' << r.psnr << " \"" << r.config.label
                     << "\"\n";
        data << "\n\n";
    }
    for (const auto* front : {&e.referenceFront, &e.multiphaseFront}) {
        for (size_t i : *front)
            if (std::isfinite(e.runs[i].psnr))
                data << e.runs[i].sequenceSeconds / frames << ' ' << e.runs[i].psnr << "\n";
        data << "\n\n";
    }
    writeTextFile(folder / "error_vs_time.dat", data.str());
    std::ostringstream cost;
    for (const EvalFrame& f : e.runs[e.defaultRun].frames)
        cost << f.index << ' ' << f.staticSeconds << ' ' << f.wallSeconds - f.staticSeconds << ' '
             << e.runs[e.referenceAtSpp].frames[static_cast<size_t>(f.index - e.first)].wallSeconds
             << "\n";
    writeTextFile(folder / "cost_per_frame.dat", cost.str());

    std::vector<std::string> written;
    std::ostringstream gp;
    for (const char* kind : {"png", "svg"}) {
        const std::string terminal = std::string(kind) == "png" ? "pngcairo size 900,560 noenhanced"
                                                                : "svg size 900,560 noenhanced";
        const std::string a = "error_vs_time." + std::string(kind);
        const std::string b = "cost_per_frame." + std::string(kind);
        gp << "set terminal " << terminal << "\nset output '" << a << "'\n"
           << "set title '" << e.name << ": error against time (truth: reference at " << e.truthSpp
           << " spp)'\nset logscale x 2\nset xlabel 'seconds per frame, whole "
           << "sequence (static work included)'\nset ylabel 'PSNR against the truth (dB)'\n"
           << "set key bottom right\nset grid\n"
           << "plot 'error_vs_time.dat' index 2 with lines lw 2 lc rgb '#3060c0' title "
              "'reference front', "
           << "'' index 0 with points pt 7 ps 1.2 lc rgb '#3060c0' title 'reference ladder', "
           << "'' index 3 with lines lw 2 lc rgb '#d04020' title 'multi-phase front', "
           << "'' index 1 with points pt 9 ps 1.2 lc rgb '#d04020' title 'multi-phase', "
           << "'' index 1 using 1:2:3 with labels offset 0.8,0.6 left font ',8' notitle\n"
           << "unset logscale x\nset output '" << b << "'\n"
           << "set title '" << e.name << ": cost per frame, multi-phase defaults'\n"
           << "set xlabel 'frame'\nset ylabel 'seconds'\nset key top right\n"
           << "plot 'cost_per_frame.dat' using 1:2 with linespoints lw 2 title 'static "
              "(dicing, tile fills)', "
           << "'' using 1:3 with linespoints lw 2 title 'dynamic', "
           << "'' using 1:4 with lines dt 2 lw 2 title 'reference frame at the same spp'\n";
        written.push_back(e.name + "/" + a);
        written.push_back(e.name + "/" + b);
    }
    writeTextFile(folder / "plots.gp", gp.str());
    const std::string command =
        "cd '" + folder.string() + "' && gnuplot plots.gp >gnuplot.log 2>&1";
    if (std::system(command.c_str()) != 0) {
        std::fprintf(stderr, "mpshade eval: gnuplot failed for %s (see %s)\n", e.name.c_str(),
                     (folder / "gnuplot.log").string().c_str());
        return {};
    }
    return written;
}

std::string reportMarkdown(const std::vector<SceneEvaluation>& scenes,
                           const std::vector<std::vector<std::string>>& plots) {
    std::ostringstream md;
    md << "# mpshade eval\n\nEach configuration renders the same frames; its error is measured "
          "against a ground truth, the reference renderer at many samples per pixel. Times "
          "are wall clock on this machine; a *whole sequence* counts building the renderer, "
          "every static phase and every frame. `docs/evaluation.md` explains the method.\n";
    for (size_t s = 0; s < scenes.size(); ++s) {
        const SceneEvaluation& e = scenes[s];
        const EvalRun& ref = e.runs[e.referenceAtSpp];
        const EvalRun& def = e.runs[e.defaultRun];
        md << "\n## " << e.name << " (`" << e.scene << "`)\n\n"
           << e.width << "x" << e.height << ", frames " << e.first << ":" << e.last << ", truth at "
           << e.truthSpp << " spp (" << e.truthFramesCached << " frames from the cache, "
           << e.truthFramesRendered << " rendered).\n\n"
           << "- **Speed at equal PSNR, whole sequence**, multi-phase defaults ("
           << def.config.label << ", " << psnrText(def.psnr) << " dB): " << speedupText(e.atDefault)
           << ".\n"
           << "- At the reference's own error at " << e.spp << " spp (" << psnrText(ref.psnr)
           << " dB): " << speedupText(e.atReferencePsnr) << ".\n"
           << "- Best configuration within the reference's ladder: "
           << (e.best.valid
                   ? e.best.label + ", " + psnrText(e.best.psnr) + " dB, " + speedupText(e.best)
                   : std::string("n/a"))
           << ".\n"
           << "- **Worst case**, a camera cut every frame (nothing reused): "
           << fmt("%.2f s", e.worstCase.sequenceSeconds) << " against the reference's "
           << fmt("%.2f s", ref.sequenceSeconds) << " at " << e.spp
           << " spp: " << fmt("%+.1f%%", 100.0 * e.worstCaseOverhead) << ".\n"
           << "- **Warm store**, a second run reading the first's shader-map tiles: "
           << fmt("%.2f s", e.warmStore.sequenceSeconds) << " (static "
           << fmt("%.2f s", e.warmStore.staticSeconds) << "), " << fmt("%.2fx", e.warmStoreSpeedup)
           << " at equal PSNR, " << fmt("%.2fx", e.warmStoreGain)
           << " the defaults'; the first run, filling the store: "
           << fmt("%.2f s", e.coldStore.sequenceSeconds) << " against "
           << fmt("%.2f s", def.sequenceSeconds) << " without one.\n\n"
           << "| configuration | knob | sequence s | static s | dynamic s/frame | steady "
              "frame s | PSNR dB | RMSE | largest | temporal RMSE | memory MB | single-phase "
              "frames |\n"
           << "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
        for (const EvalRun& r : e.runs)
            md << "| " << r.config.label << " | " << r.config.knob << " | "
               << fmt("%.2f", r.sequenceSeconds) << " | " << fmt("%.2f", r.staticSeconds) << " | "
               << fmt("%.3f", r.dynamicSecondsPerFrame) << " | "
               << fmt("%.3f", r.steadyFrameSeconds) << " | " << psnrText(r.psnr) << " | "
               << fmt("%.4f", r.rmse) << " | " << fmt("%.3f", r.maxAbs) << " | "
               << fmt("%.4f", r.temporalRmse) << " | "
               << (r.peakMemoryMb >= 0 ? fmt("%.0f", r.peakMemoryMb) : std::string("?")) << " | "
               << (r.config.multiphase ? std::to_string(r.singlePhaseFrames) : "") << " |\n";
        auto frontText = [&](const std::vector<size_t>& front) {
            std::string out;
            for (size_t i : front)
                out += (out.empty() ? "" : " -> ") + e.runs[i].config.label + " (" +
                       fmt("%.2f s", e.runs[i].sequenceSeconds) + ", " + psnrText(e.runs[i].psnr) +
                       " dB)";
            return out;
        };
        md << "\nPareto fronts (faster to more accurate): reference " << frontText(e.referenceFront)
           << "; multi-phase " << frontText(e.multiphaseFront) << ".\n";
        if (!plots[s].empty()) {
            md << "\n";
            for (const std::string& p : plots[s])
                if (p.size() > 4 && p.compare(p.size() - 4, 4, ".png") == 0)
                    md << "![" << p << "](" << p << ")\n";
        }
    }
    return md.str();
}

}  // namespace mpshade
