// split_verification.h -- whether a factoring is exact for an object's binding: the static
// part then the dynamic part against the whole shader, at points spread over the object's
// charts and over frames of the scene, output by output and channel by channel.
//
// The static part runs once, at the first frame verified (as a static run at that frame
// would: a bake() freezes its inputs there); the dynamic part and the whole shader run at
// every frame verified. A split without bake() agrees to rounding; a bake's error is what
// its frozen inputs cost at the later frames. Each stored channel is also compared with
// the static part run at each frame itself: 0 for an exact split, the drift of the stored
// value where a bake froze something.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "phases/static_phase.h"

namespace mpshade {

struct SplitVerificationOptions {
    int points = 4096;  // at most, spread as a grid over each chart (at least one a chart)
    int frames = 8;     // at most, evenly over the scene's frames, first and last included
};

// Where a difference was largest.
struct SplitPoint {
    int frame = 0;
    int chart = 0;
    float u = 0.0f, v = 0.0f;
};

struct SplitDifference {
    std::string name;          // "Ci[0]" .. "Oi[2]", or a channel's name
    double maxAbs = 0.0;       // largest |factored - whole| over points and frames
    double maxRelative = 0.0;  // largest |a - b| / max(|a|, |b|, 1)
    double rms = 0.0;
    SplitPoint worst;
};

struct SplitVerification {
    int points = 0, frames = 0;
    std::vector<SplitDifference> outputs;   // Ci then Oi, per component
    std::vector<SplitDifference> channels;  // per stored channel: drift from its own frame
    double maxRelative() const;             // over the outputs
};

// Cell centres of a k x k grid on each chart, k chosen so the total stays within `budget`;
// past `budget` charts, every so many charts' centres.
std::vector<ChartPoint> spreadChartPoints(const Surface& surface, int budget);

// How far apart two outputs are: |a - b|, 0 for two NaNs, infinite where one is finite and
// the other not (or two infinities differ); relative: over max(|a|, |b|, 1).
double outputDifference(float a, float b);
double relativeOutputDifference(float a, float b);

// Verifies object `object` of the scene `statics` was made for (its shading as the
// renderers factor it; `resources` the same scene's).
SplitVerification verifySplit(const StaticPhase& statics, const SceneResources& resources,
                              size_t object, const SplitVerificationOptions& options = {});

}  // namespace mpshade
