// band_points.h -- a band's shading points, made once a frame from the visibility buffer:
// where the dynamic shader runs and which point each fragment composites (dynamic_phase.h
// describes the shading rates).
//
// Per sample every fragment is a point. Per pixel, or per block of 2x2 pixels, the
// fragments of the block that see the same object at the same depth layer share one point
// at their centroid, on the facet of the member sample nearest to it (the first such, in
// sample order). Either way the points are grouped by object (a counting sort), so the
// dynamic shader runs over each object's points as contiguous batches.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "phases/facet_rasterizer.h"
#include "phases/sample_pattern.h"

namespace mpshade {

inline constexpr uint32_t kNoPoint = ~uint32_t{0};

// Pixel rows [row0, row1) of the image, with their samples [firstSample, endSample) in the
// layout's order, their first visibility slot and their first pixel; of those rows, the
// columns [col0, col1) (a band: every column; a refined image tile: its own). Per-band
// arrays (fragmentPoint, pixelPoint) span the rows' whole width either way.
struct BandRange {
    int row0 = 0, row1 = 0, col0 = 0, col1 = 0;
    size_t firstSample = 0, endSample = 0;
    size_t firstSlot = 0, firstPixel = 0;

    BandRange(const SampleLayout& layout, int layers, int row0, int row1);
    BandRange(const SampleLayout& layout, int layers, int row0, int row1, int col0, int col1);
    bool wholeRows(const SampleLayout& layout) const { return col0 == 0 && col1 == layout.width(); }
};

// A band's shading points and their results. Kept while the band is unfinished (its points
// whose probes found tiles missing are shaded again after the fill, the rest are not) and reused
// from frame to frame.
struct BandPoints {
    bool built = false;
    std::vector<uint32_t> object, facet;  // per shading point
    std::vector<float> x, y;              // per shading point, pixels
    std::vector<uint32_t> fragmentPoint;  // per visibility slot of the band
    // Per pixel of the band, shaded per pixel or per 2x2 pixels: its point, where that one
    // point is every sample's only fragment (its samples' fragmentPoint then unset);
    // otherwise kNoPoint. Empty when shaded per sample.
    std::vector<uint32_t> pixelPoint;
    std::vector<float> color, opacity;  // 3 per shading point, and one float more
    // Points are grouped by object: object o's are [objectStart[o], objectStart[o + 1]).
    std::vector<uint32_t> objectStart;
    bool fresh = false;             // no point shaded yet: every point is pending
    std::vector<uint32_t> pending;  // otherwise, the points still to shade
};

// A thread's buffers for making points (reused; their contents are scratch).
struct BandPointScratch {
    std::vector<uint32_t> cursor, permutation;
    std::vector<uint32_t> unsortedObject, unsortedFacet;
    std::vector<float> unsortedX, unsortedY;
    std::vector<uint8_t> member;  // per fragment of a pixel block: its group
    // Per block of a band shaded per pixel or 2x2 pixels: the object covering it whole, or
    // none (~0); after each block covered by several surfaces, its groups' end.
    std::vector<uint32_t> blockObject, groupEnd;
};

struct BandPointOptions {
    ShadingRate rate = ShadingRate::Sample;
    // Per pixel or 2x2 pixels: a pixel (block) whose samples all see one surface in front
    // takes its point from the layout's precomputed centroid and nearest sample instead of
    // grouping its fragments; the same points, bit for bit.
    bool wholePixelShortcut = true;
};

// Makes `points` for the band `range` of `vis` (over `objects` objects) and marks it built
// and fresh, its colors and opacities sized but not yet shaded.
void buildBandPoints(const SampleLayout& layout, const VisibilityBuffer& vis,
                     const BandRange& range, size_t objects, const BandPointOptions& options,
                     BandPoints& points, BandPointScratch& scratch);

}  // namespace mpshade
