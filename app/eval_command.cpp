#include "app/eval_command.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>

#include <unistd.h>
#include <nlohmann/json.hpp>

#include "app/command_line.h"
#include "app/eval_report.h"
#include "app/eval_runner.h"
#include "app/eval_truth.h"
#include "app/image_output.h"
#include "app/output_files.h"
#include "geometry/error.h"
#include "phases/reference_renderer.h"

namespace mpshade {
namespace {

using Clock = std::chrono::steady_clock;

// The ladders. Multi-phase moves one knob at a time away from its defaults, plus the
// combinations that measured on the fronts (pixel rate with more samples).
std::vector<EvalConfig> ladders(int spp, bool quick) {
    std::vector<EvalConfig> out;
    const std::vector<int> refSpp =
        quick ? std::vector<int>{1, 2, 4, 8} : std::vector<int>{1, 2, 4, 8, 16};
    std::set<int> seen(refSpp.begin(), refSpp.end());
    std::vector<int> rungs = refSpp;
    if (!seen.count(spp)) rungs.push_back(spp);  // the scene's own is always on it
    for (int s : rungs) {
        EvalConfig c;
        c.multiphase = false;
        c.knob = "spp";
        c.spp = s;
        c.label = "ref spp=" + std::to_string(s);
        out.push_back(c);
    }
    EvalConfig def;
    def.spp = spp;
    def.label = "mp default";
    out.push_back(def);
    auto add = [&](const std::string& knob, const std::string& label, auto change) {
        EvalConfig c = def;
        c.knob = knob;
        c.label = "mp " + label;
        change(c);
        out.push_back(c);
    };
    for (int s : quick ? std::vector<int>{1, 2} : std::vector<int>{1, 2, 8, 16})
        if (s != spp) add("spp", "spp=" + std::to_string(s), [&](EvalConfig& c) { c.spp = s; });
    add("single_phase_frames", "never single-phase",
        [](EvalConfig& c) { c.singlePhaseFrames = false; });
    add("shading_rate", "pixel", [](EvalConfig& c) { c.shadingRate = ShadingRate::Pixel; });
    add("shading_rate", "pixel spp=" + std::to_string(2 * spp), [&](EvalConfig& c) {
        c.shadingRate = ShadingRate::Pixel;
        c.spp = 2 * spp;
    });
    for (float f : quick ? std::vector<float>{0.6f, 1.5f} : std::vector<float>{0.4f, 0.6f, 1.5f})
        add("footprint_scale", "footprint=" + std::to_string(f).substr(0, 3),
            [&](EvalConfig& c) { c.footprintScale = f; });
    add("max_anisotropy", "aniso=4", [](EvalConfig& c) { c.maxAnisotropy = 4.0f; });
    if (quick) return out;
    add("shading_rate", "pixel spp=" + std::to_string(4 * spp), [&](EvalConfig& c) {
        c.shadingRate = ShadingRate::Pixel;
        c.spp = 4 * spp;
    });
    add("probe_filter", "trilinear", [](EvalConfig& c) { c.filter = ProbeFilter::Trilinear; });
    add("probe_filter", "ewa", [](EvalConfig& c) {
        c.filter = ProbeFilter::EWA;
        c.maxAnisotropy = 16.0f;
    });
    add("max_anisotropy", "aniso=1", [](EvalConfig& c) { c.maxAnisotropy = 1.0f; });
    add("max_anisotropy", "aniso=8", [](EvalConfig& c) { c.maxAnisotropy = 8.0f; });
    add("level_anisotropy", "level aniso=off", [](EvalConfig& c) { c.levelAnisotropy = 0.0f; });
    add("level_anisotropy", "level aniso=8", [](EvalConfig& c) { c.levelAnisotropy = 8.0f; });
    add("facet_edge", "facet edge=1", [](EvalConfig& c) { c.facetEdgePixels = 1.0f; });
    add("range", "range x0.5", [](EvalConfig& c) { c.rangeScale = 0.5f; });
    add("range", "range x2", [](EvalConfig& c) { c.rangeScale = 2.0f; });
    add("cache", "cache=16MB", [](EvalConfig& c) { c.cacheMb = 16; });
    return out;
}

class SweepProgress {
  public:
    SweepProgress(bool enabled, std::string scene, int total)
        : enabled_(enabled), scene_(std::move(scene)), total_(std::max(1, total)) {}
    void step(const std::string& what) {
        ++done_;
        if (!enabled_) return;
        const int width = 30, filled = done_ * width / total_;
        std::fprintf(stderr, "\r%s: %-22.22s [%s%s] %3d%%", scene_.c_str(), what.c_str(),
                     std::string(static_cast<size_t>(filled), '#').c_str(),
                     std::string(static_cast<size_t>(width - filled), '.').c_str(),
                     done_ * 100 / total_);
        std::fflush(stderr);
    }
    void finish() {
        if (enabled_) std::fprintf(stderr, "\n");
    }

  private:
    bool enabled_;
    std::string scene_;
    int total_, done_ = 0;
};

std::string sceneName(const std::string& path, std::set<std::string>& taken) {
    const std::filesystem::path p(path);
    std::string name = p.stem().string();
    if (name == "scene" && p.has_parent_path() && !p.parent_path().filename().empty())
        name = p.parent_path().filename().string();
    std::string unique = name;
    for (int k = 2; taken.count(unique); ++k) unique = name + "-" + std::to_string(k);
    taken.insert(unique);
    return unique;
}

// The truth's frames, from the cache where it has them, rendered (and cached) otherwise;
// counted and timed in `e`.
std::vector<Image> truthFrames(const Scene& scene, const RenderOptions& dense,
                               const std::filesystem::path& out, SceneEvaluation& e,
                               SweepProgress& progress) {
    const TruthKey key{sceneContentHash(e.scene), e.width, e.height, e.truthSpp, dense.seed};
    const std::filesystem::path truthDir = key.folder(out);
    std::vector<Image> truth;
    std::unique_ptr<ReferenceRenderer> reference;
    const auto start = Clock::now();
    for (int f = e.first; f < e.last; ++f) {
        std::optional<Image> cached = readTruthFrame(truthDir, f, e.width, e.height);
        if (cached) {
            truth.push_back(std::move(*cached));
            ++e.truthFramesCached;
        } else {
            if (!reference) reference = std::make_unique<ReferenceRenderer>(scene);
            FrameStats stats;
            truth.push_back(reference->renderFrame(f, dense, stats));
            writeTruthFrame(truthDir, f, truth.back());
            ++e.truthFramesRendered;
        }
        progress.step("truth");
    }
    e.truthSeconds = std::chrono::duration<double>(Clock::now() - start).count();
    e.truthSelfPsnr = psnrOfMse(meanSquaredError(truth[0], truth[0]));
    return truth;
}

}  // namespace

int runEvalCommand(const EvalCommandOptions& options) {
    if (options.scenes.empty())
        throw InputError({"scenes", 0, 0, {}}, "name at least one scene file");
    if (options.truthSpp < 2 || options.truthSpp > 1024)
        throw InputError({"--truth-spp", 0, 0, {}},
                         "expected 2..1024, found " + std::to_string(options.truthSpp));
    int width = 0, height = 0;
    parseImageSize(options.size, width, height);
    // Every scene is loaded (and so checked) before any work starts.
    std::vector<Scene> loaded;
    for (const std::string& path : options.scenes) loaded.push_back(loadScene(path));
    std::vector<std::pair<int, int>> ranges;
    for (size_t s = 0; s < loaded.size(); ++s) {
        int first, last;
        parseFrameRange(options.frames, loaded[s].frameCount(), first, last, options.scenes[s]);
        ranges.emplace_back(first, last);
    }
    prepareOutputFolder(options.outDir);
    const std::filesystem::path out(options.outDir);
    const bool tty = !options.quiet && isatty(STDERR_FILENO);

    std::vector<SceneEvaluation> evaluations;
    std::vector<std::vector<std::string>> plots;
    std::set<std::string> names;
    nlohmann::json doc = {{"version", 1},
                          {"truth_spp", options.truthSpp},
                          {"quick", options.quick},
                          {"scenes", nlohmann::json::array()}};
    for (size_t s = 0; s < loaded.size(); ++s) {
        const Scene& scene = loaded[s];
        SceneEvaluation e;
        e.scene = options.scenes[s];
        e.name = sceneName(e.scene, names);
        // --quick: half the width and height (a quarter of the samples), every frame: the
        // static work is amortized as in the full render.
        const int shrink = options.quick && !options.fullSize && width == 0 ? 2 : 1;
        e.width = width > 0 ? width : std::max(1, scene.settings.width / shrink);
        e.height = height > 0 ? height : std::max(1, scene.settings.height / shrink);
        e.spp = scene.settings.samplesPerPixel;
        e.first = ranges[s].first;
        e.last = ranges[s].second;
        e.truthSpp = options.truthSpp;
        const int frames = e.last - e.first;
        RenderOptions base;
        base.width = e.width;
        base.height = e.height;

        const std::vector<EvalConfig> configs = ladders(e.spp, options.quick);
        SweepProgress progress(tty, e.name, frames * static_cast<int>(configs.size() + 4));
        if (!options.quiet && !tty)
            std::fprintf(stderr, "mpshade eval: %s: %d configurations over %d frames\n",
                         e.name.c_str(), static_cast<int>(configs.size()) + 3, frames);

        // The truth, from the cache where it has it.
        // The truth's samples are drawn with another seed than the ladders': a rung at
        // the truth's own spp would otherwise be the truth itself, and the lower ones
        // might share its first samples.
        RenderOptions dense = base;
        dense.samplesPerPixel = e.truthSpp;
        dense.seed = base.seed ^ 0x9e3779b9u;
        const std::vector<Image> truth = truthFrames(scene, dense, out, e, progress);

        for (const EvalConfig& c : configs) {
            e.runs.push_back(runEvalConfig(e.scene, c, e.first, e.last, base, truth,
                                           [&] { progress.step(c.label); }));
            if (c.multiphase && c.knob == "default") e.defaultRun = e.runs.size() - 1;
            if (!c.multiphase && c.spp == e.spp) e.referenceAtSpp = e.runs.size() - 1;
        }
        EvalConfig cut = e.runs[e.defaultRun].config;
        cut.knob = "cut_every_frame";
        cut.label = "mp default, cut every frame";
        cut.cutEveryFrame = true;
        e.worstCase = runEvalConfig(e.scene, cut, e.first, e.last, base, truth,
                                    [&] { progress.step(cut.label); });
        // A store of its own, emptied first: the first run fills it, the second reads it.
        EvalConfig stored = e.runs[e.defaultRun].config;
        stored.knob = "store";
        stored.storeFolder = (out / e.name / "store").string();
        std::filesystem::remove_all(stored.storeFolder);
        stored.label = "mp default, empty store";
        e.coldStore = runEvalConfig(e.scene, stored, e.first, e.last, base, truth,
                                    [&] { progress.step(stored.label); });
        stored.label = "mp default, warm store";
        e.warmStore = runEvalConfig(e.scene, stored, e.first, e.last, base, truth,
                                    [&] { progress.step(stored.label); });
        std::filesystem::remove_all(stored.storeFolder);
        progress.finish();
        summarize(e);

        // Images of the first frame for the report: truth, reference and multi-phase.
        const std::filesystem::path folder = out / e.name;
        std::filesystem::create_directories(folder);
        writePng(truth[0], (folder / "truth_first_frame.png").string());
        plots.push_back(writePlots(e, out));
        doc["scenes"].push_back(toJson(e));
        writeTextFile(out / "eval.json", doc.dump(2) + "\n");
        evaluations.push_back(std::move(e));
        writeTextFile(out / "report.md", reportMarkdown(evaluations, plots));
        if (!options.quiet) {
            const SceneEvaluation& done = evaluations.back();
            std::fprintf(stderr,
                         "mpshade eval: %s: speedup at equal PSNR %.2fx (whole sequence, "
                         "defaults at %.2f dB), %.2fx at the reference's %.2f dB; a cut "
                         "every frame %+.1f%%; a warm store %.2fx\n",
                         done.name.c_str(), done.atDefault.sequence, done.atDefault.psnr,
                         done.atReferencePsnr.sequence, done.atReferencePsnr.psnr,
                         100.0 * done.worstCaseOverhead, done.warmStoreSpeedup);
        }
    }
    if (!options.quiet)
        std::fprintf(stderr, "mpshade eval: wrote %s, %s and the plots\n",
                     (out / "eval.json").string().c_str(), (out / "report.md").string().c_str());
    return 0;
}

}  // namespace mpshade
