// eval_metrics.h -- the arithmetic behind `mpshade eval` (docs/evaluation.md): errors of a
// sequence against its ground truth, Pareto fronts of time against error, and the time a
// ladder of reference settings would need at a given error. Plain functions of numbers, so
// they are tested against values worked out by hand.
#pragma once

#include <vector>

#include "phases/image.h"

namespace mpshade {

// PSNR in dB of a mean squared error over [0, 1] channels: 10 log10(1 / mse). An mse of 0
// (an image against itself) is +infinity.
double psnrOfMse(double mse);

// Mean squared error of RGB, each channel clamped to [0, 1]: compareImages' RMSE, squared.
// Both the same size.
double meanSquaredError(const Image& test, const Image& truth);

// The temporal error of a frame pair: the RMS over RGB of how the test's change from frame
// a to frame b differs from the truth's own change, (test_b - test_a) - (truth_b - truth_a),
// channels clamped to [0, 1] first. 0 when the test flickers exactly as the truth moves.
double temporalRmse(const Image& testA, const Image& testB, const Image& truthA,
                    const Image& truthB);

struct TimedError {
    double seconds = 0.0;  // lower is better
    double psnr = 0.0;     // higher is better
};

// Indices of the points no other point beats: none both faster (or as fast) and more
// accurate (or as accurate) with one of them strictly. Sorted by seconds ascending, so psnr
// ascends strictly along the front. Points with a non-finite time are left out.
std::vector<size_t> paretoFront(const std::vector<TimedError>& points);

struct LadderTime {
    double seconds = 0.0;
    // The psnr lies outside the ladder's range: the nearest segment was extended (time is
    // interpolated in log2 seconds, linear in dB) and the figure is an estimate.
    bool extrapolated = false;
    bool valid = false;  // false when the ladder has fewer than two distinct points
};

// The time a ladder (one mode's configurations, e.g. the reference at 1, 2, 4, 8, 16 spp)
// needs to reach `psnr`: its Pareto front, with log2(seconds) interpolated linearly in dB
// between the two front points around `psnr`. Below the front's first point the time is
// the first point's (a faster setting is not on the ladder; not counted as extrapolated
// upward, but marked).
LadderTime timeAtPsnr(const std::vector<TimedError>& ladder, double psnr);

}  // namespace mpshade
