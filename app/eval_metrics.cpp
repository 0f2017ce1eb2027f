#include "app/eval_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "phases/image_compare.h"

namespace mpshade {
namespace {

float clamp01(float x) {
    return std::isfinite(x) ? std::clamp(x, 0.0f, 1.0f) : 1.0f;
}

}  // namespace

double psnrOfMse(double mse) {
    if (mse <= 0.0) return std::numeric_limits<double>::infinity();
    return 10.0 * std::log10(1.0 / mse);
}

double meanSquaredError(const Image& test, const Image& truth) {
    const double rmse = compareImages(test, truth).rmse;
    return rmse * rmse;
}

double temporalRmse(const Image& testA, const Image& testB, const Image& truthA,
                    const Image& truthB) {
    const size_t pixels = static_cast<size_t>(truthA.width) * truthA.height;
    if (pixels == 0) return 0.0;
    double sum = 0.0;
    for (size_t p = 0; p < pixels; ++p)
        for (size_t c = 0; c < 3; ++c) {
            const size_t i = p * 4 + c;
            const double d =
                (static_cast<double>(clamp01(testB.rgba[i])) - clamp01(testA.rgba[i])) -
                (static_cast<double>(clamp01(truthB.rgba[i])) - clamp01(truthA.rgba[i]));
            sum += d * d;
        }
    return std::sqrt(sum / static_cast<double>(pixels * 3));
}

std::vector<size_t> paretoFront(const std::vector<TimedError>& points) {
    std::vector<size_t> order;
    for (size_t i = 0; i < points.size(); ++i)
        if (std::isfinite(points[i].seconds) && !std::isnan(points[i].psnr)) order.push_back(i);
    // Fastest first; among equal times the most accurate first, so it alone can enter.
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        if (points[a].seconds != points[b].seconds) return points[a].seconds < points[b].seconds;
        return points[a].psnr > points[b].psnr;
    });
    std::vector<size_t> front;
    double best = -std::numeric_limits<double>::infinity();
    for (size_t i : order)
        if (points[i].psnr > best) {
            front.push_back(i);
            best = points[i].psnr;
        }
    return front;
}

LadderTime timeAtPsnr(const std::vector<TimedError>& ladder, double psnr) {
    LadderTime out;
    const std::vector<size_t> front = paretoFront(ladder);
    // Infinite PSNR (an exact match) cannot be interpolated to; finite points only.
    std::vector<TimedError> f;
    for (size_t i : front)
        if (std::isfinite(ladder[i].psnr) && ladder[i].seconds > 0.0) f.push_back(ladder[i]);
    if (f.size() < 2 || std::isnan(psnr)) return out;
    out.valid = true;
    if (psnr <= f.front().psnr) {
        out.seconds = f.front().seconds;
        out.extrapolated = psnr < f.front().psnr;
        return out;
    }
    size_t k = 1;
    while (k + 1 < f.size() && f[k].psnr < psnr) ++k;
    const TimedError& a = f[k - 1];
    const TimedError& b = f[k];
    out.extrapolated = psnr > f.back().psnr;
    if (!std::isfinite(psnr)) {
        out.seconds = std::numeric_limits<double>::infinity();
        return out;
    }
    const double w = (psnr - a.psnr) / (b.psnr - a.psnr);
    out.seconds =
        std::exp2(std::log2(a.seconds) + w * (std::log2(b.seconds) - std::log2(a.seconds)));
    return out;
}

}  // namespace mpshade
