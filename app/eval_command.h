// eval_command.h -- `mpshade eval`: speed against error for one or more scenes
// (docs/evaluation.md). Per scene: a ground truth (the reference at --truth-spp, cached in
// the output folder), a ladder of reference settings and one of multi-phase settings, each
// timed over the same frames and measured against the truth; then the headline ratios, the
// Pareto fronts, the worst case (a cut every frame), eval.json, report.md and plots.
#pragma once

#include <string>
#include <vector>

namespace mpshade {

struct EvalCommandOptions {
    std::vector<std::string> scenes;
    std::string outDir;
    std::string frames;  // "A:B" (half-open) or "N"; default: every frame
    int truthSpp = 64;
    bool quick = false;     // shorter ladders, half the width and height: a minute or two a scene
    std::string size;       // "WxH": overrides the scenes' settings
    bool fullSize = false;  // with quick: each scene at its own size
    bool quiet = false;
};

// Returns the exit code, 0.
// Bad input throws InputError naming its place (the CLI prints it and exits 2); a file
// that cannot be written throws OutputError (exit 1).
int runEvalCommand(const EvalCommandOptions& options);

}  // namespace mpshade
