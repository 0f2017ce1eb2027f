#include "phases/sample_pattern.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <new>

#include <sys/mman.h>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "geometry/error.h"
#include "geometry/float4.h"
#include "phases/resolve_builds.h"
#include "phases/resolve_rows.h"

namespace mpshade {
namespace {

uint32_t mix32(uint32_t h) {
    h ^= h >> 16;
    h *= 0x7feb352du;
    h ^= h >> 15;
    h *= 0x846ca68bu;
    h ^= h >> 16;
    return h;
}

using ResolveRows = void (*)(const ResolveFrame&, int, int);

void resolveRowsPortable(const ResolveFrame& frame, int r0, int r1) {
    resolveRowsOf(frame, r0, r1);
}

// The rows of `build` (Fastest: the widest the processor runs).
ResolveRows resolveRowsFor(ResolveBuild build) {
    if (build == ResolveBuild::Fastest)
        build = resolveAvx512Available() ? ResolveBuild::Avx512
                : resolveAvx2Available() ? ResolveBuild::Avx2
                                         : ResolveBuild::Portable;
    MPSHADE_CHECK(resolveBuildAvailable(build));
    switch (build) {
        case ResolveBuild::Avx512:
            return resolveRowsAvx512;
        case ResolveBuild::Avx2:
            return resolveRowsAvx2;
        default:
            return resolveRowsPortable;
    }
}

}  // namespace

bool resolveBuildAvailable(ResolveBuild build) {
    switch (build) {
        case ResolveBuild::Avx512:
            return resolveAvx512Available();
        case ResolveBuild::Avx2:
            return resolveAvx2Available();
        default:
            return true;
    }
}

void* SampleLayout::allocateLarge(size_t bytes) {
    constexpr size_t kHuge = size_t{2} << 20;
    if (bytes < kHuge) {
        void* p = std::malloc(bytes > 0 ? bytes : 1);
        if (!p) throw std::bad_alloc();
        return p;
    }
    const size_t rounded = (bytes + kHuge - 1) / kHuge * kHuge;
    void* p = std::aligned_alloc(kHuge, rounded);
    if (!p) throw std::bad_alloc();
#ifdef MADV_HUGEPAGE
    madvise(p, rounded, MADV_HUGEPAGE);  // advice only: ignored where unsupported
#endif
    return p;
}

void SampleLayout::freeLarge(void* p, size_t) noexcept {
    std::free(p);
}

void samplePosition(uint32_t seed, int px, int py, int k, int spp, float& x, float& y) {
    const int nx = static_cast<int>(std::ceil(std::sqrt(static_cast<float>(spp))));
    const int ny = (spp + nx - 1) / nx;
    uint32_t h = mix32(seed ^ 0x9e3779b9u);
    h = mix32(h ^ static_cast<uint32_t>(px) * 0x85ebca6bu);
    h = mix32(h ^ static_cast<uint32_t>(py) * 0xc2b2ae35u);
    h = mix32(h ^ static_cast<uint32_t>(k) * 0x27d4eb2fu);
    const float jx = static_cast<float>(h & 0xFFFFu) * (1.0f / 65536.0f);
    const float jy = static_cast<float>(h >> 16) * (1.0f / 65536.0f);
    x = static_cast<float>(px) + (static_cast<float>(k % nx) + jx) / static_cast<float>(nx);
    y = static_cast<float>(py) + (static_cast<float>(k / nx) + jy) / static_cast<float>(ny);
}

SampleLayout::SampleLayout(int width, int height, int spp, uint32_t seed, const PixelFilter& filter)
    : width_(width), height_(height), spp_(spp), seed_(seed), stratified_(true), filter_(filter) {
    MPSHADE_CHECK(width > 0 && height > 0 && spp > 0);
    xy_.resize(static_cast<size_t>(width) * height * spp * 2);
    tbb::parallel_for(0, height, [&](int py) {
        for (int px = 0; px < width; ++px)
            for (int k = 0; k < spp; ++k) {
                const size_t s = index(px, py, k);
                samplePosition(seed, px, py, k, spp, xy_[2 * s], xy_[2 * s + 1]);
            }
    });
    prepareFilter();
}

SampleLayout::SampleLayout(int width, int height, int spp, std::vector<float> xy,
                           const PixelFilter& filter)
    : width_(width), height_(height), spp_(spp), filter_(filter), xy_(std::move(xy)) {
    MPSHADE_CHECK(width > 0 && height > 0 && spp > 0);
    MPSHADE_CHECK(xy_.size() == static_cast<size_t>(width) * height * spp * 2);
    for (int py = 0; py < height; ++py)
        for (int px = 0; px < width; ++px)
            for (int k = 0; k < spp; ++k) {
                const size_t s = index(px, py, k);
                MPSHADE_CHECK(xy_[2 * s] >= px && xy_[2 * s] < px + 1.0f);
                MPSHADE_CHECK(xy_[2 * s + 1] >= py && xy_[2 * s + 1] < py + 1.0f);
            }
    prepareFilter();
}

bool SampleLayout::matches(int width, int height, int spp, uint32_t seed,
                           const PixelFilter& filter) const {
    return stratified_ && width == width_ && height == height_ && spp == spp_ && seed == seed_ &&
           filter == filter_;
}

void SampleLayout::prepareFilter() {
    MPSHADE_CHECK(filter_.radius > 0.0f && filter_.radius <= 8.0f && filter_.sigma > 0.0f);
    MPSHADE_CHECK(spp_ <= 16384);  // 4 spp fits the quads' nearest-sample index
    prepareCentroids();
    prepareQuadCentroids();
    const size_t n = count();
    fx_.resize(n);
    fy_.resize(n);
    tbb::parallel_for(0, height_, [&](int py) {
        for (size_t s = index(0, py, 0); s < index(0, py, 0) + static_cast<size_t>(width_) * spp_;
             ++s) {
            fx_[s] = static_cast<int32_t>(std::lround(xy_[2 * s] * 256.0f));
            fy_[s] = static_cast<int32_t>(std::lround(xy_[2 * s + 1] * 256.0f));
        }
    });
    prepareTaps();
    preparePixelWeights();
    prepareBlockWeights();
    prepareInverseSums();
}

void SampleLayout::prepareCentroids() {
    const size_t pixels = static_cast<size_t>(width_) * height_;
    centroid_.resize(2 * pixels);
    nearest_.resize(pixels);
    tbb::parallel_for(0, height_, [&](int py) {
        for (size_t p = static_cast<size_t>(py) * width_; p < static_cast<size_t>(py + 1) * width_;
             ++p) {
            float sx = 0.0f, sy = 0.0f;
            for (int k = 0; k < spp_; ++k) {
                sx += xy_[2 * (p * spp_ + k)];
                sy += xy_[2 * (p * spp_ + k) + 1];
            }
            const float cx = sx / static_cast<float>(spp_), cy = sy / static_cast<float>(spp_);
            float best = 1e30f;
            int nearest = 0;
            for (int k = 0; k < spp_; ++k) {
                const float dx = xy_[2 * (p * spp_ + k)] - cx,
                            dy = xy_[2 * (p * spp_ + k) + 1] - cy;
                if (dx * dx + dy * dy < best) {
                    best = dx * dx + dy * dy;
                    nearest = k;
                }
            }
            centroid_[2 * p] = cx;
            centroid_[2 * p + 1] = cy;
            nearest_[p] = static_cast<uint16_t>(nearest);
        }
    });
}

void SampleLayout::prepareQuadCentroids() {
    const int qw = width_ / 2, qh = height_ / 2;
    quadCentroid_.resize(2 * static_cast<size_t>(qw) * qh);
    quadNearest_.resize(static_cast<size_t>(qw) * qh);
    tbb::parallel_for(0, qh, [&](int qy) {
        for (int qx = 0; qx < qw; ++qx) {
            float sx = 0.0f, sy = 0.0f;
            for (int py = 2 * qy; py < 2 * qy + 2; ++py)
                for (int px = 2 * qx; px < 2 * qx + 2; ++px)
                    for (int k = 0; k < spp_; ++k) {
                        sx += x(index(px, py, k));
                        sy += y(index(px, py, k));
                    }
            const float count = static_cast<float>(4 * spp_);
            const float cx = sx / count, cy = sy / count;
            float best = 1e30f;
            int nearest = 0, m = 0;
            for (int py = 2 * qy; py < 2 * qy + 2; ++py)
                for (int px = 2 * qx; px < 2 * qx + 2; ++px)
                    for (int k = 0; k < spp_; ++k, ++m) {
                        const float dx = x(index(px, py, k)) - cx, dy = y(index(px, py, k)) - cy;
                        if (dx * dx + dy * dy < best) {
                            best = dx * dx + dy * dy;
                            nearest = m;
                        }
                    }
            const size_t b = static_cast<size_t>(qy) * qw + qx;
            quadCentroid_[2 * b] = cx;
            quadCentroid_[2 * b + 1] = cy;
            quadNearest_[b] = static_cast<uint16_t>(nearest);
        }
    });
}

void SampleLayout::prepareTaps() {
    // A sample inside pixel q is at distance in (o - 1/2, o + 1/2] from the centre of
    // pixel q + o, so it reaches the pixels with |o| < radius + 1/2.
    reach_ = static_cast<int>(std::ceil(filter_.radius + 0.5f)) - 1;
    taps_ = 2 * reach_ + 1;
    const double inv2s2 = 1.0 / (2.0 * filter_.sigma * filter_.sigma);
    const double tail = std::exp(-static_cast<double>(filter_.radius) * filter_.radius * inv2s2);
    auto weight = [&](double d) {
        d = std::fabs(d);
        return d < filter_.radius ? std::max(0.0, std::exp(-d * d * inv2s2) - tail) : 0.0;
    };
    const size_t taps = static_cast<size_t>(taps_);
    weights_.resize(count() * 2 * taps);
    tbb::parallel_for(0, height_, [&](int py) {
        for (int px = 0; px < width_; ++px)
            for (int k = 0; k < spp_; ++k) {
                const size_t s = index(px, py, k);
                for (int o = -reach_; o <= reach_; ++o) {
                    const size_t t = s * 2 * taps + static_cast<size_t>(o + reach_);
                    weights_[t] = static_cast<float>(weight(xy_[2 * s] - (px + o + 0.5)));
                    weights_[t + taps] =
                        static_cast<float>(weight(xy_[2 * s + 1] - (py + o + 0.5)));
                }
            }
    });
}

// Per pixel, its samples' weights summed, towards each pixel in reach (taps x taps, rows
// then columns), for pixels whose samples are all alike.
void SampleLayout::preparePixelWeights() {
    const size_t taps = static_cast<size_t>(taps_);
    pixelWeights_.resize(static_cast<size_t>(width_) * height_ * taps * taps);
    tbb::parallel_for(0, height_, [&](int py) {
        for (int px = 0; px < width_; ++px) {
            float* pw = &pixelWeights_[(static_cast<size_t>(py) * width_ + px) * taps * taps];
            std::fill(pw, pw + taps * taps, 0.0f);
            for (int k = 0; k < spp_; ++k) {
                const float* w = &weights_[index(px, py, k) * 2 * taps];
                for (size_t oy = 0; oy < taps; ++oy)
                    for (size_t ox = 0; ox < taps; ++ox) pw[oy * taps + ox] += w[taps + oy] * w[ox];
            }
        }
    });
}

// Per whole 2x2 block, for a filter reaching one pixel around: its four pixels' summed
// weights towards the 4 x 4 pixels it reaches (rows then columns, from the pixel up and left
// of it).
void SampleLayout::prepareBlockWeights() {
    blockWeights_.clear();
    if (reach_ == 1) {
        const int bw = width_ / 2, bh = height_ / 2;
        blockWeights_.resize(static_cast<size_t>(bw) * bh * 16);
        tbb::parallel_for(0, bh, [&](int by) {
            for (int bx = 0; bx < bw; ++bx) {
                float* bwt = &blockWeights_[(static_cast<size_t>(by) * bw + bx) * 16];
                std::fill(bwt, bwt + 16, 0.0f);
                for (int dy = 0; dy < 2; ++dy)
                    for (int dx = 0; dx < 2; ++dx) {
                        const float* pw =
                            &pixelWeights_[(static_cast<size_t>(2 * by + dy) * width_ + 2 * bx +
                                            dx) *
                                           9];
                        for (int oy = 0; oy < 3; ++oy)
                            for (int ox = 0; ox < 3; ++ox)
                                bwt[(oy + dy) * 4 + ox + dx] += pw[oy * 3 + ox];
                    }
            }
        });
    }
}

void SampleLayout::prepareInverseSums() {
    const size_t taps = static_cast<size_t>(taps_);
    inverseSum_.resize(static_cast<size_t>(width_) * height_);
    tbb::parallel_for(0, height_, [&](int py) {
        for (int px = 0; px < width_; ++px) {
            double sum = 0.0;
            for (int qy = std::max(0, py - reach_); qy <= std::min(height_ - 1, py + reach_); ++qy)
                for (int qx = std::max(0, px - reach_); qx <= std::min(width_ - 1, px + reach_);
                     ++qx)
                    for (int k = 0; k < spp_; ++k) {
                        const size_t s = index(qx, qy, k);
                        const float* w = &weights_[s * 2 * taps];
                        sum += static_cast<double>(w[static_cast<size_t>(px - qx + reach_)]) *
                               w[taps + static_cast<size_t>(py - qy + reach_)];
                    }
            inverseSum_[static_cast<size_t>(py) * width_ + px] =
                sum > 0.0 ? static_cast<float>(1.0 / sum) : 0.0f;
        }
    });
}

void SampleLayout::resolve(const float* rgba, const uint8_t* uniform, Image& out, bool quads,
                           ResolveBuild build) const {
    if (out.width != width_ || out.height != height_) out = Image(width_, height_);
    // Bands of output rows in parallel. Within a band, every sample of the rows in reach is
    // read once and added to the pixels it reaches in the band: its y weight towards the
    // row times its x weight towards the column. A pixel whose samples all hold the same
    // value (one surface shaded once for the pixel) is added once, with its samples'
    // weights summed in advance. Inside the image (the filter reaching one pixel around),
    // a pixel's samples are summed in registers and the nine pixels they reach read and
    // written once: read-modify-writes, each waiting on the last through memory, were what
    // the resolve's time went to (Resolve benchmarks: 1.5-1.8x faster).
    // Shaded per 2x2 pixels, a block whose four pixels are alike and hold the same color
    // goes in one step: 16 pixels reached, against 36 for four pixels (1.3x faster
    // resolves at one sample a pixel; looking for such blocks in frames shaded otherwise
    // costs more than it finds).
    ResolveFrame f = resolveFrame(rgba, uniform, quads);
    f.pixels = out.rgba.data();
    const auto rows = resolveRowsFor(build);
    constexpr int kBand = 8;
    tbb::parallel_for(0, (height_ + kBand - 1) / kBand, [&](int band) {
        const int r0 = band * kBand, r1 = std::min(height_, r0 + kBand);
        rows(f, r0, r1);
    });
}

ResolveFrame SampleLayout::resolveFrame(const float* rgba, const uint8_t* uniform,
                                        bool quads) const {
    ResolveFrame f;
    f.rgba = rgba;
    f.uniform = uniform;
    f.weights = weights_.data();
    f.pixelWeights = pixelWeights_.data();
    f.blockWeights = blockWeights_.data();
    f.inverseSum = inverseSum_.data();
    f.width = width_, f.height = height_, f.reach = reach_;
    f.taps = static_cast<size_t>(taps_), f.spp = static_cast<size_t>(spp_);
    f.blocks = quads && uniform && reach_ == 1 && !blockWeights_.empty();
    f.stride = width_;  // the whole image's window and columns
    f.col0 = 0, f.col1 = width_;
    return f;
}

void SampleLayout::resolveRects(const float* rgba, const uint8_t* uniform, Image& out,
                                std::span<const PixelRect> rects, bool quads,
                                ResolveBuild build) const {
    MPSHADE_CHECK(out.width == width_ && out.height == height_);
    const ResolveFrame frame = resolveFrame(rgba, uniform, quads);
    const auto rows = resolveRowsFor(build);
    tbb::enumerable_thread_specific<std::vector<float>> windows;
    tbb::parallel_for(size_t{0}, rects.size(), [&](size_t i) {
        const PixelRect& r = rects[i];
        MPSHADE_CHECK(0 <= r.x0 && r.x0 <= r.x1 && r.x1 <= width_ && 0 <= r.y0 && r.y0 <= r.y1 &&
                      r.y1 <= height_);
        if (r.area() == 0) return;
        ResolveFrame f = frame;
        // The samples of every column reaching the rectangle, from an even column (a 2x2
        // block is met at its left one); the window holds every column they are added to
        // (a block's reach one more to the right).
        f.col0 = std::max(0, r.x0 - reach_) & ~1;
        f.col1 = std::min(width_, r.x1 + reach_);
        f.x0 = std::max(0, f.col0 - reach_);
        f.stride = std::min(width_, f.col1 + reach_ + 1) - f.x0;
        f.y0 = r.y0;
        std::vector<float>& window = windows.local();
        window.resize(static_cast<size_t>(f.stride) * static_cast<size_t>(r.y1 - r.y0) * 4);
        f.pixels = window.data();
        rows(f, r.y0, r.y1);
        const size_t columns = static_cast<size_t>(r.x1 - r.x0) * 4;
        for (int y = r.y0; y < r.y1; ++y)
            std::copy_n(
                window.data() + (static_cast<size_t>(y - r.y0) * f.stride + r.x0 - f.x0) * 4,
                columns, out.pixel(r.x0, y));
    });
}

std::vector<PixelRect> SampleLayout::pixelsReading(std::span<const PixelRect> changed) const {
    // Each row's columns in reach of a changed pixel, as sorted, merged intervals; then
    // runs of rows with the same intervals, one rectangle per interval.
    std::vector<std::vector<std::pair<int, int>>> rows(static_cast<size_t>(height_));
    for (const PixelRect& r : changed) {
        if (r.area() <= 0) continue;
        const int x0 = std::max(0, r.x0 - reach_), x1 = std::min(width_, r.x1 + reach_);
        for (int y = std::max(0, r.y0 - reach_); y < std::min(height_, r.y1 + reach_); ++y)
            rows[static_cast<size_t>(y)].emplace_back(x0, x1);
    }
    for (auto& row : rows) {
        std::sort(row.begin(), row.end());
        size_t merged = 0;
        for (const auto& span : row)
            if (merged > 0 && span.first <= row[merged - 1].second)
                row[merged - 1].second = std::max(row[merged - 1].second, span.second);
            else
                row[merged++] = span;
        row.resize(merged);
    }
    std::vector<PixelRect> rects;
    for (int y = 0; y < height_;) {
        int end = y + 1;
        while (end < height_ && rows[static_cast<size_t>(end)] == rows[static_cast<size_t>(y)])
            ++end;
        for (const auto& [x0, x1] : rows[static_cast<size_t>(y)]) rects.push_back({x0, y, x1, end});
        y = end;
    }
    return rects;
}

void SampleBuffer::reset(std::shared_ptr<const SampleLayout> l) {
    layout = std::move(l);
    width = layout->width();
    height = layout->height();
    spp = layout->spp();
    rgba.assign(layout->count() * 4, 0.0f);
}

}  // namespace mpshade
