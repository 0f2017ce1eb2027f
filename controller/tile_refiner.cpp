#include "controller/tile_refiner.h"

#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

#include "geometry/float4.h"

namespace mpshade {
namespace {

using Clock = std::chrono::steady_clock;

// A channel clamped to [0, 1] as compareImages clamps it; a NaN (which compareImages would
// carry through) counts as 0, so one bad pixel cannot make every priority NaN.
float clamp01(float v) {
    return std::min(1.0f, std::max(0.0f, v));
}

// Sum over the rectangle's pixels of the squared RGB difference between a and b, each
// channel clamped to [0, 1] first (compareImages' measure).
double squaredDifference(const Image& a, const Image& b, const PixelRect& r) {
    double sum = 0.0;
    for (int y = r.y0; y < r.y1; ++y) {
        const float* pa = &a.rgba[4 * (static_cast<size_t>(y) * a.width + r.x0)];
        const float* pb = &b.rgba[4 * (static_cast<size_t>(y) * b.width + r.x0)];
        for (int x = r.x0; x < r.x1; ++x, pa += 4, pb += 4)
            for (int k = 0; k < 3; ++k) {
                const double d = clamp01(pa[k]) - clamp01(pb[k]);
                sum += d * d;
            }
    }
    return sum;
}

// An exponential running mean: the first measurement, then half old and half new.
void runningMean(double& mean, double value) {
    mean = mean < 0.0 ? value : 0.5 * (mean + value);
}

}  // namespace

void TileRefiner::layOut(int width, int height) {
    if (width == width_ && height == height_) return;
    width_ = width, height_ = height;
    tiles_.clear();
    tileSize_ = std::max(2, options_.tileSize & ~1);  // even: 2x2 blocks stay whole
    const int ts = tileSize_;
    for (int y = 0; y < height; y += ts)
        for (int x = 0; x < width; x += ts) {
            Tile t;
            t.rect = {x, y, std::min(width, x + ts), std::min(height, y + ts)};
            tiles_.push_back(t);
        }
    errorPerContrast_.assign(errorPerContrast_.size(), -1.0);
    meansKept_ = false;
}

// Per tile: whether it sees any surface, its contrast in the cheap image (each pixel against
// its right and lower neighbours) and its temporal error.
void TileRefiner::measure(const DynamicPhase& dynamic, const Image& image) {
    const VisibilityBuffer& vis = dynamic.visibility();
    const size_t pixels = static_cast<size_t>(width_) * height_;
    const size_t spp = pixels > 0 ? vis.count.size() / pixels : 0;
    tbb::parallel_for(size_t{0}, tiles_.size(), [&](size_t i) {
        Tile& t = tiles_[i];
        const PixelRect& r = t.rect;
        bool seen = false;
        float contrast = 0.0f;
        float mean[3] = {0, 0, 0};
        // A pixel's RGBA as one vector (its alpha lane summed too, and left out): the
        // contrast of a 1280x720 frame had taken 6 ms a channel at a time, more than
        // refinement then had left to refine in.
        const Float4 zero = splatFloat4(0.0f), one = splatFloat4(1.0f);
        const auto clamp = [&](Float4 v) {
            v = v > zero ? v : zero;  // a NaN counts as 0, as clamp01 has it
            return v < one ? v : one;
        };
        Float4 squares = zero, sums = zero;
        for (int y = r.y0; y < r.y1; ++y) {
            const size_t row = static_cast<size_t>(y) * width_;
            for (size_t k = (row + r.x0) * spp; k < (row + r.x1) * spp && !seen; ++k)
                seen = vis.count[k] > 0;
            const float* c = &image.rgba[4 * (row + r.x0)];
            const size_t down = y + 1 < height_ ? 4 * static_cast<size_t>(width_) : 0;
            for (int x = r.x0; x < r.x1; ++x, c += 4) {
                const Float4 v = clamp(loadFloat4(c));
                const Float4 dx = v - clamp(loadFloat4(x + 1 < width_ ? c + 4 : c));
                const Float4 dy = v - clamp(loadFloat4(c + down));
                squares += dx * dx + dy * dy;
                sums += v;
            }
        }
        for (int k = 0; k < 3; ++k) contrast += squares[k], mean[k] = sums[k];
        t.seen = seen;
        t.contrast = contrast;
        double change = 0.0;
        for (int k = 0; k < 3; ++k) {
            mean[k] /= r.area();
            if (meansKept_) change += (mean[k] - t.mean[k]) * (mean[k] - t.mean[k]);
            t.cheapMean[k] = mean[k];
        }
        // As squared differences summed over the tile's pixels, the contrast's units.
        t.error = (errorPerContrast_.back() > 0.0 ? errorPerContrast_.back() : 1.0) * contrast +
                  options_.temporalWeight * change * r.area();
    });
}

// The tiles that see a surface, by priority, highest first.
std::vector<uint32_t> TileRefiner::order() {
    double errors = 0.0, ages = 0.0;
    for (const Tile& t : tiles_)
        if (t.seen) errors += t.error, ages += t.age;
    std::vector<uint32_t> order;
    for (uint32_t i = 0; i < tiles_.size(); ++i) {
        Tile& t = tiles_[i];
        if (!t.seen) continue;
        t.priority = (errors > 0.0 ? options_.errorWeight * t.error / errors : 0.0) +
                     (ages > 0.0 ? options_.ageWeight * t.age / ages : 0.0);
        if (t.refinedLast) t.priority *= 1.0 + options_.hysteresis;
        order.push_back(i);
    }
    // Ties (flat tiles never refined) in image order: the same view gives the same order.
    std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
        return tiles_[a].priority > tiles_[b].priority;
    });
    return order;
}

void TileRefiner::refine(DynamicPhase& dynamic, const RefineStep& base,
                         std::span<const RefineStep> better, Clock::time_point deadline,
                         Image& image, RefineStats& stats, std::vector<TileRequest>& missing) {
    const auto start = Clock::now();
    stats = RefineStats{};
    better = better.first(std::min<size_t>(better.size(), RefineStats::kMaxSteps - 1));
    if (better.empty() || image.width <= 0 || image.height <= 0) return;
    stats.ran = true;
    stats.steps = static_cast<int>(better.size()) + 1;
    for (int k = 0; k < stats.steps; ++k) {
        const RefineStep& step = k == 0 ? base : better[static_cast<size_t>(k) - 1];
        stats.rateAt[k] = step.rate;
        stats.footprintAt[k] = step.footprintScale;
    }
    if (start + std::chrono::duration_cast<Clock::duration>(
                    std::chrono::duration<double>(lastPriorities_)) >=
        deadline) {
        // No time left past the priorities (as long as they last took): not even they are
        // worth their time.
        stats.pixelsAt[0] = static_cast<uint64_t>(image.width) * image.height;
        stats.estimatedPsnr = -1.0;
        return;
    }
    layOut(image.width, image.height);
    if (!(base == base_) ||
        !std::equal(better.begin(), better.end(), better_.begin(), better_.end())) {
        base_ = base;
        better_.assign(better.begin(), better.end());
        errorPerContrast_.assign(better.size() + 1, -1.0);
    }
    stats.tileSize = tileSize_;
    measure(dynamic, image);
    const std::vector<uint32_t> ranked = order();
    std::vector<PixelRect> rects;
    rects.reserve(ranked.size());
    for (uint32_t i : ranked) rects.push_back(tiles_[i].rect);
    if (options_.maxTiles > 0 && rects.size() > static_cast<size_t>(options_.maxTiles))
        rects.resize(static_cast<size_t>(options_.maxTiles));
    for (Tile& t : tiles_) t.step = 0;
    const auto passes = Clock::now();
    lastPriorities_ = std::chrono::duration<double>(passes - start).count();
    // One pass per better step, each over the tiles in order; a pass cut short by the
    // deadline ends refinement.
    for (size_t k = 0; k < better.size(); ++k) {
        const RefineCounts counts =
            dynamic.refine(rects, {better[k].rate, better[k].footprintScale, deadline}, missing);
        stats.shadingPoints += counts.shadingPoints;
        for (size_t n = 0; n < counts.tiles; ++n) tiles_[ranked[n]].step = static_cast<int>(k) + 1;
        if (counts.tiles > 0)
            stats.threshold =
                counts.tiles < ranked.size() ? tiles_[ranked[counts.tiles - 1]].priority : 0.0;
        if (counts.tiles < rects.size()) break;
    }
    stats.passSeconds = std::chrono::duration<double>(Clock::now() - passes).count();
    // The refined tiles' cheap pixels kept for their gain (account), then only the pixels
    // that read the refined tiles' samples resolved again: at 1280x720 resolving the whole
    // image again had taken 5 ms, and refinement kept twice that in reserve.
    std::vector<PixelRect> refined;
    for (const Tile& t : tiles_)
        if (t.step > 0) refined.push_back(t.rect);
    if (!refined.empty()) {
        if (cheap_.width != image.width || cheap_.height != image.height)
            cheap_ = Image(image.width, image.height);
        for (const PixelRect& r : refined)
            for (int y = r.y0; y < r.y1; ++y)
                std::copy_n(image.pixel(r.x0, y), 4 * static_cast<size_t>(r.x1 - r.x0),
                            cheap_.pixel(r.x0, y));
        stats.resolveSeconds = dynamic.resolveAgain(image, refined);
    }
    account(cheap_, image, static_cast<int>(better.size()), dynamic.layout()->filterReach(), stats);
    if (!refined.empty()) {
        lastPass_ = stats.passSeconds;
        lastFinish_ = std::chrono::duration<double>(Clock::now() - passes).count() - lastPass_;
    }
    stats.seconds = std::chrono::duration<double>(Clock::now() - start).count();
}

// What refinement changed, the change per unit of contrast it measured per step, the
// estimate of the error left, and each tile's state for the next frame.
void TileRefiner::account(const Image& cheap, const Image& image, int best, int reach,
                          RefineStats& stats) {
    gain_.assign(tiles_.size(), 0.0);
    // The final image differs from the cheap one in the tiles refined and, by the filter's
    // reach, the tiles that far around them: only there are the means measured again (a
    // pass over the whole image had been 1.5 ms at 1280x720).
    const int across = (width_ + tileSize_ - 1) / tileSize_;
    const int down = static_cast<int>(tiles_.size()) / std::max(1, across);
    const int ring = (reach + tileSize_ - 1) / tileSize_;
    changed_.assign(tiles_.size(), 0);
    for (size_t i = 0; i < tiles_.size(); ++i) {
        if (tiles_[i].step == 0) continue;
        const int tx = static_cast<int>(i) % across, ty = static_cast<int>(i) / across;
        for (int y = std::max(0, ty - ring); y <= std::min(down - 1, ty + ring); ++y)
            for (int x = std::max(0, tx - ring); x <= std::min(across - 1, tx + ring); ++x)
                changed_[static_cast<size_t>(y) * across + x] = 1;
    }
    tbb::parallel_for(size_t{0}, tiles_.size(), [&](size_t i) {
        Tile& t = tiles_[i];
        if (t.step > 0) gain_[i] = squaredDifference(cheap, image, t.rect);
        if (!changed_[i]) {
            std::copy_n(t.cheapMean, 3, t.mean);
            return;
        }
        double mean[3] = {0, 0, 0};
        for (int y = t.rect.y0; y < t.rect.y1; ++y) {
            const float* c = &image.rgba[4 * (static_cast<size_t>(y) * width_ + t.rect.x0)];
            for (int x = t.rect.x0; x < t.rect.x1; ++x, c += 4)
                for (int k = 0; k < 3; ++k) mean[k] += clamp01(c[k]);
        }
        for (int k = 0; k < 3; ++k) t.mean[k] = static_cast<float>(mean[k] / t.rect.area());
    });
    meansKept_ = true;
    std::vector<double> stepGain(static_cast<size_t>(best) + 1, 0.0), stepContrast = stepGain;
    double gained = 0.0;
    uint64_t gainedPixels = 0;
    for (size_t i = 0; i < tiles_.size(); ++i) {
        const Tile& t = tiles_[i];
        stats.pixelsAt[t.step] += static_cast<uint64_t>(t.rect.area());
        if (t.seen) ++stats.tiles;
        if (t.step == 0) continue;
        ++stats.refined[t.step];
        gained += gain_[i];
        gainedPixels += static_cast<uint64_t>(t.rect.area());
        stepGain[static_cast<size_t>(t.step)] += gain_[i];
        stepContrast[static_cast<size_t>(t.step)] += t.contrast;
    }
    stats.gainMse = gainedPixels > 0 ? gained / (3.0 * static_cast<double>(gainedPixels)) : 0.0;
    for (size_t k = 1; k < stepGain.size(); ++k)
        if (stepContrast[k] > 0.0) runningMean(errorPerContrast_[k], stepGain[k] / stepContrast[k]);
    // The error left against the best step, per tile: its contrast times the change per
    // unit of contrast that going to the best step measured, less the change its own
    // refinement made (the two taken as adding up). Until the best step is measured, the
    // best ratio measured stands for it (an underestimate).
    double full = 0.0;
    for (size_t k = 1; k < errorPerContrast_.size(); ++k)
        full = std::max(full, errorPerContrast_[k]);
    if (errorPerContrast_.back() > 0.0) full = errorPerContrast_.back();
    double left = 0.0;
    for (size_t i = 0; i < tiles_.size(); ++i) {
        const Tile& t = tiles_[i];
        if (t.seen && t.step != best) left += std::max(0.0, full * t.contrast - gain_[i]);
    }
    const double mse = left / (3.0 * static_cast<double>(width_) * height_);
    if (!(full > 0.0))
        stats.estimatedPsnr = -1.0;  // nothing measured yet
    else
        stats.estimatedPsnr = mse > 1e-10 ? std::min(99.0, -10.0 * std::log10(mse)) : 99.0;
    for (Tile& t : tiles_) {
        t.age = t.step == best ? 0 : t.age + 1;
        t.refinedLast = t.step > 0;
    }
}

}  // namespace mpshade
