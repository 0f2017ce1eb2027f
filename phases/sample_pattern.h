// sample_pattern.h -- where the sub-pixel samples of a frame lie, and how they become pixels.
// Every renderer (reference and multi-phase) uses these, so images differ only by how
// each sample's color was computed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "phases/image.h"
#include "phases/resolve_frame.h"

namespace mpshade {

// Sample k (of spp) of pixel (px, py): stratified jittered. The pixel is cut into an
// nx x ny grid (nx = ceil(sqrt(spp)), ny = ceil(spp / nx)); sample k takes cell
// (k mod nx, k div nx) and a hashed offset inside it, so positions depend only on
// (seed, px, py, k). Returns image coordinates in pixels (continuous, y down).
void samplePosition(uint32_t seed, int px, int py, int k, int spp, float& x, float& y);

// Which build of the resolve runs (SampleLayout::resolve): the fastest the processor has, the
// baseline, or one for a wider instruction set (only where resolveBuildAvailable()).
enum class ResolveBuild { Fastest, Portable, Avx2, Avx512 };
bool resolveBuildAvailable(ResolveBuild build);

// The pixel reconstruction filter: a truncated Gaussian (pbrt-v4's GaussianFilter),
// f(d) = max(0, exp(-d^2 / (2 sigma^2)) - exp(-r^2 / (2 sigma^2))) separably in x and y.
struct PixelFilter {
    float radius = 1.5f;  // pixels, in (0, 8]
    float sigma = 0.5f;   // pixels, > 0
    bool operator==(const PixelFilter&) const = default;
};

// The samples of every frame of one size: their positions (continuous, and on the
// rasterizer's 1/256-pixel grid) and the reconstruction filter's weights, computed once
// and reused by every frame (positions do not change from frame to frame, so neither do
// the weights: a frame's resolve is multiply-adds only). Sample k of pixel (px, py) has
// index (py * width + px) * spp + k, and lies inside its pixel: px <= x < px + 1.
class SampleLayout {
  public:
    // The stratified pattern of samplePosition().
    SampleLayout(int width, int height, int spp, uint32_t seed, const PixelFilter& filter = {});
    // Explicit positions, 2 floats per sample in index order, each inside its pixel.
    SampleLayout(int width, int height, int spp, std::vector<float> xy,
                 const PixelFilter& filter = {});

    int width() const { return width_; }
    int height() const { return height_; }
    int spp() const { return spp_; }
    // Pixels the reconstruction filter reaches around a pixel (a pixel reads the samples of
    // the pixels this far, in x and in y).
    int filterReach() const { return reach_; }
    size_t count() const { return xy_.size() / 2; }
    size_t index(int px, int py, int k) const {
        return (static_cast<size_t>(py) * width_ + px) * spp_ + k;
    }
    float x(size_t s) const { return xy_[2 * s]; }
    float y(size_t s) const { return xy_[2 * s + 1]; }
    // x and y of every sample, in index order (2 * count() floats): for loops that store
    // through other pointers, where x() and y() would reload the array each time.
    const float* positions() const { return xy_.data(); }
    // Per pixel: the mean of its samples' positions (summed in sample order, then divided by
    // spp), and which of its samples lies nearest to it (the first, in sample order, of
    // those nearest). A surface covering a whole pixel is shaded there, per pixel.
    float centroidX(size_t pixel) const { return centroid_[2 * pixel]; }
    float centroidY(size_t pixel) const { return centroid_[2 * pixel + 1]; }
    int nearestToCentroid(size_t pixel) const { return nearest_[pixel]; }
    // The same per block of 2x2 pixels at even (px, py), whole inside the image (summed row
    // by row, pixel by pixel, sample by sample); the nearest is 0..4 spp - 1 in that order.
    // block = (py / 2) * (width / 2) + px / 2.
    float quadCentroidX(size_t block) const { return quadCentroid_[2 * block]; }
    float quadCentroidY(size_t block) const { return quadCentroid_[2 * block + 1]; }
    int nearestToQuadCentroid(size_t block) const { return quadNearest_[block]; }
    // On the 1/256-pixel grid: round(x * 256), round(y * 256).
    const int32_t* fixedX() const { return fx_.data(); }
    const int32_t* fixedY() const { return fy_.data(); }
    bool matches(int width, int height, int spp, uint32_t seed, const PixelFilter& filter) const;

    // Pixels from per-sample RGBA (4 floats per sample, index order): each pixel is the
    // filter-weighted mean of the samples within the filter's radius of its centre.
    // `uniform` (per pixel, may be null): 1 where every sample of the pixel holds the same
    // RGBA as its first, which is then read once. `quads`: the frame was shaded once per
    // 2x2 pixels, so whole 2x2 blocks of uniform pixels holding one RGBA are looked for and
    // read once (with `uniform` only). `out` keeps its storage when its size is the
    // layout's. `build`: the fastest the processor runs (AVX-512 where it has it), or the
    // baseline's; the same bits either way.
    void resolve(const float* rgba, const uint8_t* uniform, Image& out, bool quads = false,
                 ResolveBuild build = ResolveBuild::Fastest) const;
    // The pixels of `rects` (inside the image, disjoint) resolved again into `out`, which
    // has the layout's size, the same bits resolve() gives them; the rest of `out` is left
    // as it is. Each rectangle is resolved in a window of its own holding the columns its
    // samples reach, so what it reads and adds is exactly what the whole image's resolve
    // reads and adds for those pixels, in the same order. For a frame changed in a few
    // places (refinement by tile): their cost, not the image's.
    void resolveRects(const float* rgba, const uint8_t* uniform, Image& out,
                      std::span<const PixelRect> rects, bool quads = false,
                      ResolveBuild build = ResolveBuild::Fastest) const;
    // The pixels whose resolve reads a sample of the pixels of `changed` (those within the
    // filter's reach of them), as disjoint rectangles, row strips in order: where a frame
    // changed only there, resolveRects() of these makes the image resolve() would.
    std::vector<PixelRect> pixelsReading(std::span<const PixelRect> changed) const;

  private:
    // Resizing leaves the elements unset: every one is written before it is read, and
    // zeroing tens of megabytes first had been a third of building a layout.
    template <class T>
    struct Unset : std::allocator<T> {
        template <class U>
        struct rebind {
            using other = Unset<U>;
        };
        template <class U>
        void construct(U* p) noexcept {
            ::new (static_cast<void*>(p)) U;
        }
        T* allocate(size_t n) { return static_cast<T*>(allocateLarge(n * sizeof(T))); }
        void deallocate(T* p, size_t n) noexcept { freeLarge(p, n * sizeof(T)); }
    };
    // Buffers of 2 MiB or more are 2 MiB-aligned and asked to be backed by huge pages, so a
    // first touch faults once per 2 MiB instead of once per 4 KiB.
    static void* allocateLarge(size_t bytes);
    static void freeLarge(void* p, size_t bytes) noexcept;
    template <class T>
    using Buffer = std::vector<T, Unset<T>>;

    // What the shading points and the resolve read, made once with the layout: each pixel's
    // and each 2x2 block's centroid and nearest sample, the positions in fixed point, the
    // filter's separable taps per sample, their sums per pixel and per block, and each
    // pixel's inverse weight sum.
    void prepareFilter();
    // What every resolve reads, with the whole image as its window and columns (its output
    // pixels left for the caller to set).
    ResolveFrame resolveFrame(const float* rgba, const uint8_t* uniform, bool quads) const;
    void prepareCentroids();
    void prepareQuadCentroids();
    void prepareTaps();
    void preparePixelWeights();
    void prepareBlockWeights();
    void prepareInverseSums();

    int width_ = 0, height_ = 0, spp_ = 1;
    uint32_t seed_ = 0;
    bool stratified_ = false;
    PixelFilter filter_;
    std::vector<float> xy_;
    Buffer<int32_t> fx_, fy_;
    Buffer<float> centroid_;        // 2 per pixel
    Buffer<uint16_t> nearest_;      // per pixel
    Buffer<float> quadCentroid_;    // 2 per whole 2x2 block
    Buffer<uint16_t> quadNearest_;  // per whole 2x2 block
    // A sample reaches the pixels within `reach_` columns and rows of its own; per sample,
    // taps_ = 2 reach_ + 1 weights across (towards px - reach_ ... px + reach_), then as many
    // down.
    int reach_ = 1, taps_ = 3;
    Buffer<float> weights_;
    Buffer<float> pixelWeights_;  // per pixel: taps x taps, its samples' weights summed
    Buffer<float> blockWeights_;  // per whole 2x2 block (reach 1): 4 x 4, summed
    Buffer<float> inverseSum_;    // per pixel: 1 / the sum of the weights reaching it
};

// Per-sample results of one frame, in its layout's order.
struct SampleBuffer {
    std::shared_ptr<const SampleLayout> layout;
    int width = 0, height = 0, spp = 1;
    std::vector<float> rgba;  // 4 floats per sample: composited color over the background, alpha

    void reset(std::shared_ptr<const SampleLayout> l);
    size_t index(int px, int py, int k) const {
        return (static_cast<size_t>(py) * width + px) * spp + k;
    }
};

}  // namespace mpshade
