// eval_report.h -- what `mpshade eval` concludes for one scene, and how it is written:
// eval.json (docs/evaluation.md lists its keys), report.md, and the plots (gnuplot, PNG
// and SVG).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/eval_metrics.h"
#include "app/eval_runner.h"

namespace mpshade {

// A speed ratio at equal error: the reference's time at a PSNR over multi-phase's.
struct EqualErrorSpeedup {
    std::string label;          // the multi-phase configuration
    double psnr = 0.0;          // the PSNR compared at
    double sequence = 0.0;      // whole sequence, every static phase counted
    double steady = 0.0;        // steady frames (median after the first)
    bool extrapolated = false;  // the reference's ladder did not reach this PSNR
    bool valid = false;
};

struct SceneEvaluation {
    std::string scene;  // as given
    std::string name;   // its folder under the output folder
    int width = 0, height = 0, spp = 0, first = 0, last = 0;
    int truthSpp = 0;
    int truthFramesCached = 0, truthFramesRendered = 0;
    double truthSeconds = 0.0;
    double truthSelfPsnr = 0.0;  // the truth against itself: +infinity
    std::vector<EvalRun> runs;   // the reference ladder, then multi-phase's
    EvalRun worstCase;           // multi-phase defaults with a cut every frame
    // Multi-phase defaults with an empty store (filling it: what writing costs), then again
    // reading it: a second run of an unchanged scene.
    EvalRun coldStore, warmStore;
    size_t defaultRun = 0;      // index in runs of multi-phase at every default
    size_t referenceAtSpp = 0;  // index of the reference at the scene's spp
    std::vector<size_t> referenceFront, multiphaseFront;  // indices in runs
    EqualErrorSpeedup atDefault, best, atReferencePsnr;
    double worstCaseOverhead = 0.0;  // cut-every-frame sequence / reference's at equal spp - 1
    // The warm store's whole-sequence speedup at the defaults' PSNR (its images are the
    // defaults'), and the ratio of it to the defaults' own (atDefault.sequence).
    double warmStoreSpeedup = 0.0, warmStoreGain = 0.0;
};

// Fills the fronts and the headline ratios from the runs.
void summarize(SceneEvaluation& e);

nlohmann::json toJson(const SceneEvaluation& e);

// Writes the scene's plots into dir/e.name and returns the files written, relative to dir
// (none, with a warning on stderr, when gnuplot is not installed).
std::vector<std::string> writePlots(const SceneEvaluation& e, const std::filesystem::path& dir);

// report.md for every scene evaluated.
std::string reportMarkdown(const std::vector<SceneEvaluation>& scenes,
                           const std::vector<std::vector<std::string>>& plots);

}  // namespace mpshade
