#include "controller/quality_regulator.h"

#include <algorithm>

#include "geometry/error.h"

namespace mpshade {
namespace {

double pointsPerPixel(ShadingRate rate, int spp) {
    switch (rate) {
        case ShadingRate::Sample:
            return static_cast<double>(spp);
        case ShadingRate::Pixel:
            return 1.0;
        case ShadingRate::Quad:
            return 0.25;
    }
    return 1.0;
}

}  // namespace

QualityRegulator::QualityRegulator(ShadingRate sceneRate, int spp,
                                   const QualityRegulatorOptions& options)
    : options_(options) {
    if (sceneRate == ShadingRate::Sample) steps_.push_back({ShadingRate::Sample, 1.0f});
    if (sceneRate != ShadingRate::Quad) {
        steps_.push_back({ShadingRate::Pixel, 1.0f});
        steps_.push_back({ShadingRate::Pixel, 2.0f});
    }
    steps_.push_back({ShadingRate::Quad, 1.0f});
    steps_.push_back({ShadingRate::Quad, 2.0f});
    if (spp > 2) steps_.push_back({ShadingRate::Quad, 2.0f, spp / 2});
    if (spp > 1) steps_.push_back({ShadingRate::Quad, 2.0f, 1});
    lastFullSamples_ = 0;
    for (int k = 0; k < levels(); ++k)
        if (steps_[static_cast<size_t>(k)].samplesPerPixel == 0) lastFullSamples_ = k;
    // Until measured: as if the whole dynamic phase scaled with the shading points (an
    // overestimate: rasterization and resolve do not).
    ratioAbove_.assign(steps_.size(), 1.0);
    for (size_t k = 1; k < steps_.size(); ++k)
        ratioAbove_[k] = pointsPerPixel(steps_[k - 1].rate, std::max(1, spp)) /
                         pointsPerPixel(steps_[k].rate, std::max(1, spp));
}

double QualityRegulator::share(int level) const {
    // The best step and the cheapest at the request's samples per pixel have the whole
    // budget: the first needs no refining, and below the second only fewer samples remain.
    if (level == 0 || level >= lastFullSamples_) return 1.0;
    return options_.refinedShare;
}

void QualityRegulator::calibrate(std::span<const double> seconds, double budget) {
    MPSHADE_CHECK(seconds.size() == steps_.size());
    // A lower step never costs more than the one above it in the model; a measurement
    // that says so is noise, so ratios stay at least 1.
    for (size_t k = 1; k < steps_.size(); ++k)
        ratioAbove_[k] = seconds[k] > 0.0 ? std::max(1.0, seconds[k - 1] / seconds[k]) : 1.0;
    const double target = 0.5 * (options_.slowDownAt + options_.speedUpAt) * budget;
    current_ = levels() - 1;
    for (int k = 0; k < levels(); ++k)
        if (seconds[static_cast<size_t>(k)] <= target * share(k)) {
            current_ = k;
            break;
        }
    calm_ = probeCalm_ = 0;
    lastLevel_ = -1;
}

void QualityRegulator::update(const FrameStats& stats, double budget) {
    const double dynamic = stats.dynamic.seconds();
    const bool reused = stats.dynamic.viewReused;
    // Neighbouring steps on consecutive frames: their ratio, measured on nearly one view --
    // and both shaded afresh, or both on a still view's kept inputs: a frame that only runs
    // the dynamic shader costs a fraction of one that shades afresh, whatever its step.
    if (lastLevel_ >= 0 && dynamic > 0.0 && lastDynamic_ > 0.0 && reused == lastReused_) {
        const int below = std::max(lastLevel_, current_);
        if (std::abs(lastLevel_ - current_) == 1) {
            const double upper = lastLevel_ < current_ ? lastDynamic_ : dynamic;
            const double lower = lastLevel_ < current_ ? dynamic : lastDynamic_;
            ratioAbove_[static_cast<size_t>(below)] = std::max(1.0, upper / lower);
        }
    }
    // The budget of a frame at the current step, and of one at the step above.
    const double here = share(current_) * budget;
    const double above = share(std::max(0, current_ - 1)) * budget;
    const bool wasOver = lastLevel_ == current_ && lastDynamic_ > options_.slowDownAt * here;
    lastLevel_ = current_;
    lastDynamic_ = dynamic;
    lastReused_ = reused;
    if (!reused) {
        freshLevel_ = current_;
        freshDynamic_ = dynamic;
    }
    // One frame over the share may be the machine (a frame's time varies by a tenth or
    // more): a step down waits for a second one, unless the frame nearly took the budget.
    if (dynamic > options_.dropAt * here || (dynamic > options_.slowDownAt * here && wasOver)) {
        current_ = std::min(current_ + 1, levels() - 1);
        calm_ = probeCalm_ = 0;
        return;
    }
    if (dynamic > options_.slowDownAt * here || current_ == 0) {
        calm_ = probeCalm_ = 0;
        return;
    }
    // The step above's first frame shades afresh (its view is new to the kept inputs): on a
    // still view, predicted from this step's last fresh frame, not from the replays.
    const double base =
        reused && freshLevel_ == current_ ? std::max(dynamic, freshDynamic_) : dynamic;
    const double predicted = base * ratioAbove_[static_cast<size_t>(current_)];
    if (predicted >= options_.speedUpAt * above) {
        calm_ = 0;
        probeCalm_ = predicted < options_.dropAt * above ? probeCalm_ + 1 : 0;
        if (probeCalm_ >= options_.probeFrames) {
            --current_;
            probeCalm_ = 0;
        }
        return;
    }
    probeCalm_ = 0;
    if (++calm_ >= options_.calmFrames) {
        --current_;
        calm_ = 0;
    }
}

}  // namespace mpshade
