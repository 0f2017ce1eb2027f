// mpshade -- the command line. Exit codes: 0 success, 1 internal failure, 2 bad input.
#include <cstdio>
#include <exception>
#include <new>

#include <tbb/global_control.h>
#include <CLI/CLI.hpp>

#include "app/compare_command.h"
#include "app/eval_command.h"
#include "app/factor_command.h"
#include "app/output_files.h"
#include "app/play_command.h"
#include "app/profile_command.h"
#include "app/render_command.h"
#include "app/store_command.h"
#include "geometry/error.h"

namespace {

// TBB's worker threads ended and joined before the process exits rather than left ending
// while exit() runs: LeakSanitizer's check at exit stops every thread, and a worker caught
// ending made it crash now and then ("Tracer caught signal 11", an intermittent failure of
// the sanitized tests).
struct WorkerThreadsJoinedAtExit {
    tbb::task_scheduler_handle handle{tbb::attach{}};
    WorkerThreadsJoinedAtExit() = default;
    WorkerThreadsJoinedAtExit(const WorkerThreadsJoinedAtExit&) = delete;
    WorkerThreadsJoinedAtExit& operator=(const WorkerThreadsJoinedAtExit&) = delete;
    ~WorkerThreadsJoinedAtExit() { tbb::finalize(handle, std::nothrow); }
};

}  // namespace

int main(int argc, char** argv) {
    const WorkerThreadsJoinedAtExit workers;
    CLI::App app{"mpshade: multi-phase procedural shading"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "mpshade 0.1.0");

    mpshade::RenderCommandOptions render;
    CLI::App* renderCmd =
        app.add_subcommand("render", "Render frames of a scene to OpenEXR and PNG");
    renderCmd->add_option("scene", render.scene, "Scene file (.json)")->required();
    renderCmd->add_option("--out", render.outDir, "Output folder (created if missing)")->required();
    renderCmd
        ->add_option("--mode", render.mode,
                     "Renderer: multiphase (static phase per object, dynamic phase per frame) or "
                     "reference (single-phase: exact geometry, whole shaders)")
        ->capture_default_str();
    renderCmd->add_option("--frames", render.frames,
                          "Frames A:B (half-open; 0:2 is frames 0 and 1) or N");
    renderCmd->add_option("--size", render.size, "Image size WxH (overrides the scene)");
    renderCmd->add_option("--spp", render.spp, "Samples per pixel (overrides the scene)");
    renderCmd->add_option("--seed", render.seed, "Seed of the sample positions")
        ->capture_default_str();
    renderCmd->add_option("--shading-rate", render.shadingRate,
                          "Multiphase: run the dynamic shader per 'sample', per 'pixel' or per "
                          "2x2 pixels, 'quad' (overrides the scene)");
    renderCmd->add_option("--footprint-scale", render.footprintScale,
                          "Multiphase: shader map texels per shading point spacing, inverted "
                          "(default 1; larger reads coarser levels: faster, blurrier)");
    renderCmd
        ->add_option("--footprints", render.footprints,
                     "Multiphase: 'measured': each object's footprint widened as far as its "
                     "measured error allows, at the first frame that shows it well; 'uniform': "
                     "every object's alike")
        ->capture_default_str();
    renderCmd->add_flag("--no-single-phase", render.noSinglePhase,
                        "Multiphase: every frame multi-phase, even where its static work would "
                        "cost more than rendering the frames asked for single-phase");
    renderCmd
        ->add_option("--view-lookahead", render.viewLookahead,
                     "Multiphase: an object's static phase may be built for the view up to this "
                     "many frames ahead whose range holds the present frame, so a moving camera "
                     "re-runs it less often (0: always the present view)")
        ->capture_default_str();
    renderCmd->add_flag("--quiet", render.quiet, "No progress bar");
    renderCmd->add_option("--cache-mb", render.cacheMb,
                          "Multiphase: memory budget of the shader maps' tiles, MB (default 96; "
                          "a frame's own tiles are kept even beyond it)");
    renderCmd->add_option("--memory-mb", render.memoryMb,
                          "Refuse a render estimated to need more memory than this (MB; "
                          "default: 3/4 of physical memory)");
    renderCmd->add_flag(
        "--compare", render.compare,
        "Multiphase: also render the reference; report PSNR and speed in stats.json (every "
        "frame multi-phase, as with --no-single-phase)");

    renderCmd->add_option("--truth-spp", render.truthSpp,
                          "With --compare: also measure both renderers against the reference "
                          "at this many samples per pixel");
    renderCmd->add_flag("--cost-images", render.costImages,
                        "Multiphase: also write cost_NNNN.exr and .png, the shading points and "
                        "the dynamic shader's cost units per pixel");
    renderCmd->add_flag("--skip-existing", render.skipExisting,
                        "Render no frame whose EXR and PNG are in --out already (a retried "
                        "farm task)");
    renderCmd->add_option("--plan-frames", render.planFrames,
                          "Plan over frames A:B (holding --frames) and render those before "
                          "--frames first, unwritten: each frame then the bits a render of A:B "
                          "gives (a farm's shards)");
    renderCmd->add_flag("--shard-stats", render.shardStats,
                        "Write stats_A_B.json (the frames asked for) instead of stats.json, so "
                        "shards sharing --out keep their own");
    mpshade::addRunOptions(*renderCmd, render.run);

    mpshade::FactorCommandOptions factor;
    CLI::App* factorCmd = app.add_subcommand(
        "factor", "Split a shader into its static and dynamic parts for a scene binding");
    factorCmd->add_option("shader", factor.shader,
                          "Shader file (.sl); with --scene and --object, default the object's");
    factorCmd->add_option("--scene", factor.scene,
                          "Scene whose binding to use: of --object, or of every object");
    factorCmd->add_option("--object", factor.object, "Object in the scene");
    factorCmd->add_flag("--json", factor.json, "Machine-readable output");
    factorCmd->add_flag("--dump", factor.dump, "Also print the IR of both parts");
    factorCmd->add_flag("--verify", factor.verify,
                        "With --scene: the split against the whole shader over the object's "
                        "charts and the scene's frames (exit 1 over --tolerance)");
    factorCmd->add_option("--store", factor.store,
                          "What-if: store this expression (line:column, or a variable's name); "
                          "compared with the split without");
    factorCmd->add_option("--repeat", factor.repeat,
                          "What-if: repeat this expression every frame (line:column, or a "
                          "variable's name)");
    factorCmd->add_option("--tolerance", factor.tolerance,
                          "--verify: the largest relative difference allowed (default 1e-5)");
    factorCmd
        ->add_option("--store-above-cost", factor.storeAboveCost,
                     "Store a static value only if its work costs more than this per point "
                     "(cost units; 0: store every one)")
        ->capture_default_str()
        ->check(CLI::Range(0, 1 << 30));

    mpshade::CompareCommandOptions compare;
    CLI::App* compareCmd = app.add_subcommand(
        "compare", "The error of an image against a reference image (PSNR, RMSE, largest error)");
    compareCmd->add_option("image", compare.test, "Image measured (EXR, PNG, ...)")->required();
    compareCmd->add_option("reference", compare.reference, "Image it is measured against")
        ->required();
    compareCmd->add_flag("--json", compare.json, "Machine-readable output");
    compareCmd->add_option(
        "--diff", compare.difference,
        "Also write |image - reference| per channel, times --gain (.exr or .png)");
    compareCmd->add_option("--gain", compare.gain, "Scale of the --diff image")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);

    mpshade::EvalCommandOptions eval;
    CLI::App* evalCmd = app.add_subcommand(
        "eval", "Speed against error: ladders of both renderers against a ground truth");
    evalCmd->add_option("scenes", eval.scenes, "Scene files (.json)")->required();
    evalCmd->add_option("--out", eval.outDir, "Output folder (created if missing)")->required();
    evalCmd->add_option("--frames", eval.frames,
                        "Frames A:B (half-open) or N; default every frame");
    evalCmd
        ->add_option("--truth-spp", eval.truthSpp,
                     "Samples per pixel of the ground truth (the reference renderer)")
        ->capture_default_str();
    evalCmd->add_flag(
        "--quick", eval.quick,
        "Shorter ladders at half the width and height (unless --size): a minute or two");
    evalCmd->add_option("--size", eval.size, "Image size WxH (overrides the scenes)");
    evalCmd->add_flag("--full-size", eval.fullSize,
                      "With --quick: each scene at its own size, not half of it");
    evalCmd->add_flag("--quiet", eval.quiet, "No progress or summary on stderr");

    mpshade::ProfileCommandOptions profile;
    CLI::App* profileCmd = app.add_subcommand(
        "profile",
        "What each phase costs, per object and per frame: profile.md and a Chrome trace "
        "(trace.json)");
    profileCmd->add_option("scene", profile.scene, "Scene file (.json)")->required();
    profileCmd->add_option("--out", profile.outDir, "Output folder (created if missing)")
        ->required();
    profileCmd->add_option("--frames", profile.frames,
                           "Frames A:B (half-open) or N; default every frame");
    profileCmd->add_option("--size", profile.size, "Image size WxH (overrides the scene)");
    profileCmd->add_option("--spp", profile.spp, "Samples per pixel (overrides the scene)");
    profileCmd->add_option("--seed", profile.seed, "Seed of the sample positions")
        ->capture_default_str();
    profileCmd->add_flag("--quiet", profile.quiet, "No progress or summary on stderr");
    mpshade::addRunOptions(*profileCmd, profile.run);

    mpshade::PlayCommandOptions play;
    CLI::App* playCmd = app.add_subcommand(
        "play", "Play a scene back at a locked frame rate: each frame gets 1/fps seconds");
    playCmd->add_option("scene", play.scene, "Scene file (.json)")->required();
    playCmd->add_option("--out", play.outDir, "Output folder (created if missing)")->required();
    playCmd->add_option("--fps", play.fps, "Frames per second: each frame's budget is 1/fps")
        ->capture_default_str();
    playCmd->add_option("--frames", play.frames,
                        "Frames A:B (half-open) or N; default every frame");
    playCmd->add_option("--size", play.size, "Image size WxH (overrides the scene)");
    playCmd->add_option("--spp", play.spp, "Samples per pixel (overrides the scene)");
    playCmd->add_option("--seed", play.seed, "Seed of the sample positions")->capture_default_str();
    playCmd
        ->add_option("--cache-mb", play.cacheMb,
                     "Memory budget of the shader maps' tiles, MB (least recently used out "
                     "first; the coarsest levels stay)")
        ->capture_default_str();
    playCmd->add_flag("--no-write", play.noWrite, "Measure without the disk: stats.json only");
    playCmd->add_flag("--no-prefetch", play.noPrefetch,
                      "Fill no tiles ahead of the frames that ask for them (for comparisons)");
    playCmd->add_flag("--no-background-fills", play.noBackgroundFills,
                      "Fill missing tiles only in frames' slack, on no worker thread alongside "
                      "them (for comparisons)");
    playCmd->add_flag("--no-background-rebuilds", play.noBackgroundRebuilds,
                      "Re-dice objects whose view left their range only within frames' time, on "
                      "no worker thread alongside them (for comparisons)");
    playCmd
        ->add_option("--refine", play.refine,
                     "'on': each frame, once shaded at its step, refined by image tile at finer "
                     "rates in order of need in the time left; 'off': the whole frame at one step")
        ->capture_default_str();
    playCmd
        ->add_option("--refine-tile", play.refineTile,
                     "Refinement's image tiles, pixels a side (even, 4..256)")
        ->capture_default_str();
    playCmd
        ->add_option("--footprints", play.footprints,
                     "'measured': each object's footprint measured before the clock as `render` "
                     "measures it; 'uniform': every object's alike")
        ->capture_default_str();
    playCmd->add_option(
        "--compare-to", play.compareTo,
        "Folder of constant-quality frames (`render` at the same size): each played "
        "frame's PSNR against its frame there, and the temporal error, in stats.json "
        "and the summary");
    playCmd->add_flag("--quiet", play.quiet, "No progress or summary on stderr");
    mpshade::addRunOptions(*playCmd, play.run);

    mpshade::BakeCommandOptions bake;
    CLI::App* bakeCmd = app.add_subcommand(
        "bake", "Fill the shader-map store with every tile the frames read (no images)");
    bakeCmd->add_option("scene", bake.scene, "Scene file (.json)")->required();
    bakeCmd->add_option("--frames", bake.frames,
                        "Frames A:B (half-open) or N; default every frame");
    bakeCmd->add_option("--size", bake.size, "Image size WxH (overrides the scene)");
    bakeCmd->add_option("--spp", bake.spp, "Samples per pixel (overrides the scene)");
    bakeCmd->add_option("--seed", bake.seed, "Seed of the sample positions")->capture_default_str();
    bakeCmd->add_flag("--quiet", bake.quiet, "No progress or summary");
    mpshade::addRunOptions(*bakeCmd, bake.run);

    mpshade::StoreCommandOptions store;
    CLI::App* storeCmd =
        app.add_subcommand("store", "What a shader-map store holds; clean-up; export");
    storeCmd->require_subcommand(1);
    CLI::App* storeInfo = storeCmd->add_subcommand("info", "Maps, tiles and bytes in the store");
    storeInfo->add_option("--store", store.store, "Store folder (default as render's)");
    storeInfo->add_flag("--json", store.json, "Machine-readable output");
    CLI::App* storeGc =
        storeCmd->add_subcommand("gc", "Remove maps unused longest until the store fits");
    storeGc->add_option("--store", store.store, "Store folder (default as render's)");
    storeGc->add_option("--max-mb", store.maxMb, "Size to keep the store under, MB")->required();
    CLI::App* storeExport = storeCmd->add_subcommand(
        "export", "Write an object's stored map as mip-mapped OpenEXR, a file per chart");
    storeExport->add_option("scene", store.scene, "Scene file (.json)")->required();
    storeExport->add_option("--object", store.object, "Object in the scene")->required();
    storeExport->add_option("--out", store.outDir, "Output folder (created if missing)")
        ->required();
    storeExport->add_option("--store", store.store, "Store folder (default as render's)");
    storeExport->add_option("--max-size", store.maxSize, "Widest level written, texels")
        ->capture_default_str();

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::fprintf(stderr, "mpshade: error: %s\nRun 'mpshade --help' for usage.\n", e.what());
        return 2;
    }
    try {
        if (renderCmd->parsed())
            return mpshade::runWithThreads(render.run,
                                           [&] { return mpshade::runRenderCommand(render); });
        if (factorCmd->parsed()) return mpshade::runFactorCommand(factor);
        if (compareCmd->parsed()) return mpshade::runCompareCommand(compare);
        if (evalCmd->parsed()) return mpshade::runEvalCommand(eval);
        if (profileCmd->parsed())
            return mpshade::runWithThreads(profile.run,
                                           [&] { return mpshade::runProfileCommand(profile); });
        if (bakeCmd->parsed())
            return mpshade::runWithThreads(bake.run, [&] { return mpshade::runBakeCommand(bake); });
        if (storeCmd->parsed()) {
            store.action = storeInfo->parsed() ? "info" : storeGc->parsed() ? "gc" : "export";
            return mpshade::runStoreCommand(store);
        }
        if (playCmd->parsed())
            return mpshade::runWithThreads(play.run, [&] { return mpshade::runPlayCommand(play); });
    } catch (const mpshade::InputError& e) {
        // Bad input, its place named in the message (file:line:col, JSON path, option).
        std::fprintf(stderr, "mpshade: %s\n", e.what());
        return 2;
    } catch (const mpshade::OutputError& e) {
        std::fprintf(stderr, "mpshade: error: %s\n", e.what());
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "mpshade: internal error: %s\n", e.what());
        return 1;
    }
    return 0;
}
