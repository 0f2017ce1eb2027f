#include "phases/band_points.h"

#include <algorithm>

namespace mpshade {

BandRange::BandRange(const SampleLayout& layout, int layers, int row0_, int row1_)
    : BandRange(layout, layers, row0_, row1_, 0, layout.width()) {}

BandRange::BandRange(const SampleLayout& layout, int layers, int row0_, int row1_, int col0_,
                     int col1_)
    : row0(row0_),
      row1(row1_),
      col0(col0_),
      col1(col1_),
      firstSample(layout.index(0, row0_, 0)),
      endSample(layout.index(0, row1_, 0)),
      firstSlot(firstSample * static_cast<size_t>(layers)),
      firstPixel(firstSample / static_cast<size_t>(layout.spp())) {}

namespace {

// Sizes the point arrays to objectStart's total, its counts already prefix-summed.
void sizePoints(BandPoints& pts, size_t objects) {
    for (size_t o = 0; o < objects; ++o) pts.objectStart[o + 1] += pts.objectStart[o];
    const size_t points = pts.objectStart[objects];
    pts.object.resize(points), pts.facet.resize(points);
    pts.x.resize(points), pts.y.resize(points);
}

// Calls f(sample) for every sample of the range's rows and columns that holds a fragment.
template <typename F>
void forEachCoveredSample(const SampleLayout& layout, const BandRange& r, const uint8_t* count,
                          F&& f) {
    for (int py = r.row0; py < r.row1; ++py)
        for (size_t smp = layout.index(r.col0, py, 0); smp < layout.index(r.col1, py, 0); ++smp)
            if (count[smp]) f(smp);
}

// samplePoints with one layer (every object opaque): a sample holds at most one fragment,
// its slot the sample itself. The counts and cursors are kept in registers over each run of
// one object's samples: incremented in memory sample after sample, each waited on the last
// one's store (the counting sort's chain), most of the time this took.
void samplePointsOneLayer(const SampleLayout& layout, const VisibilityBuffer& vis,
                          const BandRange& r, size_t objects, BandPoints& pts,
                          BandPointScratch& s) {
    const uint8_t* count = vis.count.data();
    const uint32_t* object = vis.object.data();
    const uint32_t* facet = vis.facet.data();
    pts.pixelPoint.clear();
    // No object yet (a band may have none, and a frame no objects at all).
    constexpr uint32_t kNone = ~uint32_t{0};
    uint32_t current = kNone;
    uint32_t run = 0;
    forEachCoveredSample(layout, r, count, [&](size_t smp) {
        if (object[smp] != current) {
            if (current != kNone) pts.objectStart[current + 1] += run;
            current = object[smp], run = 0;
        }
        ++run;
    });
    if (current != kNone) pts.objectStart[current + 1] += run;
    sizePoints(pts, objects);
    s.cursor.assign(pts.objectStart.begin(), pts.objectStart.end() - 1);
    uint32_t* const pointObject = pts.object.data();
    uint32_t* const pointFacet = pts.facet.data();
    float* const pointX = pts.x.data();
    float* const pointY = pts.y.data();
    uint32_t* const fragmentPoint = pts.fragmentPoint.data();
    current = kNone;
    uint32_t at = 0;
    forEachCoveredSample(layout, r, count, [&](size_t smp) {
        if (object[smp] != current) {
            if (current != kNone) s.cursor[current] = at;
            current = object[smp], at = s.cursor[current];
        }
        pointObject[at] = current;
        pointFacet[at] = facet[smp];
        pointX[at] = layout.x(smp);
        pointY[at] = layout.y(smp);
        fragmentPoint[smp - r.firstSlot] = at++;
    });
}

// Per sample: a point per fragment, placed by object as it is made (a counting sort).
void samplePoints(const SampleLayout& layout, const VisibilityBuffer& vis, const BandRange& r,
                  size_t objects, BandPoints& pts, BandPointScratch& s) {
    const int layers = vis.layers;
    pts.pixelPoint.clear();
    for (int py = r.row0; py < r.row1; ++py)
        for (size_t smp = layout.index(r.col0, py, 0); smp < layout.index(r.col1, py, 0); ++smp)
            for (int l = 0; l < vis.count[smp]; ++l)
                ++pts.objectStart[vis.object[smp * layers + l] + 1];
    sizePoints(pts, objects);
    s.cursor.assign(pts.objectStart.begin(), pts.objectStart.end() - 1);
    for (int py = r.row0; py < r.row1; ++py)
        for (size_t smp = layout.index(r.col0, py, 0); smp < layout.index(r.col1, py, 0); ++smp)
            for (int l = 0; l < vis.count[smp]; ++l) {
                const size_t slot = smp * layers + l;
                const uint32_t o = vis.object[slot];
                const uint32_t at = s.cursor[o]++;
                pts.object[at] = o;
                pts.facet[at] = vis.facet[slot];
                pts.x[at] = layout.x(smp);
                pts.y[at] = layout.y(smp);
                pts.fragmentPoint[slot - r.firstSlot] = at;
            }
}

// Per pixel or per block of 2x2 pixels: the points of the band's blocks in the order made,
// then grouped by object.
class BlockPoints {
  public:
    BlockPoints(const SampleLayout& layout, const VisibilityBuffer& vis, const BandRange& r,
                int block, BandPoints& pts, BandPointScratch& s)
        : layout_(layout),
          vis_(vis),
          r_(r),
          block_(block),
          layers_(vis.layers),
          spp_(layout.spp()),
          pixelSlots_(static_cast<size_t>(layout.spp()) * vis.layers),
          pts_(pts),
          s_(s) {
        s.unsortedObject.clear(), s.unsortedFacet.clear();
        s.unsortedX.clear(), s.unsortedY.clear();
        // Only the range's own pixels are read back (a refined tile's: its columns).
        const size_t width = static_cast<size_t>(layout.width());
        if (r.wholeRows(layout)) {
            pts.pixelPoint.assign(static_cast<size_t>(r.row1 - r.row0) * width, kNoPoint);
        } else {
            pts.pixelPoint.resize(static_cast<size_t>(r.row1 - r.row0) * width);
            for (int y = r.row0; y < r.row1; ++y) {
                const auto row =
                    pts.pixelPoint.begin() + static_cast<std::ptrdiff_t>((y - r.row0) * width);
                std::fill(row + r.col0, row + r.col1, kNoPoint);
            }
        }
        s.member.resize(static_cast<size_t>(block * block) * pixelSlots_);
    }

    // The common case: one surface covers every sample of the pixel, in front. Its point is
    // the pixel's precomputed centroid, on the facet of its nearest sample: what
    // groupFragments finds.
    bool wholePixel(int bx, int by) {
        const size_t first = layout_.index(bx, by, 0);
        bool whole = vis_.count[first] == 1;
        const uint32_t o = whole ? vis_.object[first * layers_] : 0;
        for (int k = 1; k < spp_ && whole; ++k)
            whole = vis_.count[first + k] == 1 && vis_.object[(first + k) * layers_] == o;
        if (!whole) return false;
        // Not first / spp: a 64-bit division a pixel was a tenth of this step's time.
        const size_t pixel = static_cast<size_t>(by) * static_cast<size_t>(layout_.width()) +
                             static_cast<size_t>(bx);
        const size_t nearest = first + static_cast<size_t>(layout_.nearestToCentroid(pixel));
        pts_.pixelPoint[pixelAt(bx, by)] = add(o, vis_.facet[nearest * layers_],
                                               layout_.centroidX(pixel), layout_.centroidY(pixel));
        return true;
    }

    // The same for a whole 2x2 block (bx, by even, the block inside the image): its four
    // pixels' samples all see one surface, in front.
    bool wholeQuad(int bx, int by) {
        const size_t firsts[4] = {layout_.index(bx, by, 0), layout_.index(bx + 1, by, 0),
                                  layout_.index(bx, by + 1, 0), layout_.index(bx + 1, by + 1, 0)};
        bool whole = vis_.count[firsts[0]] == 1;
        const uint32_t o = whole ? vis_.object[firsts[0] * layers_] : 0;
        for (int q = 0; q < 4 && whole; ++q)
            for (int k = 0; k < spp_ && whole; ++k)
                whole =
                    vis_.count[firsts[q] + k] == 1 && vis_.object[(firsts[q] + k) * layers_] == o;
        if (!whole) return false;
        const size_t quad = static_cast<size_t>(by / 2) * (layout_.width() / 2) + bx / 2;
        const int m = layout_.nearestToQuadCentroid(quad);
        const size_t nearest = firsts[m / spp_] + static_cast<size_t>(m % spp_);
        const uint32_t point = add(o, vis_.facet[nearest * layers_], layout_.quadCentroidX(quad),
                                   layout_.quadCentroidY(quad));
        for (int dy = 0; dy < 2; ++dy)
            for (int dx = 0; dx < 2; ++dx) pts_.pixelPoint[pixelAt(bx + dx, by + dy)] = point;
        return true;
    }

    // The general case: the block's fragments grouped by surface (object and layer; past 64
    // surfaces the rest merge into the first), each group's point at its centroid on the
    // facet of the member sample nearest to it.
    void groupFragments(int bx, int by, int x1, int y1) {
        struct Group {
            uint32_t object;
            int layer;
            float sx, sy;
            int count;
        };
        Group groups[64];
        int groupCount = 0;
        forEachFragment(bx, by, x1, y1, [&](size_t smp, int l, size_t m) {
            const uint32_t o = vis_.object[smp * layers_ + l];
            int g = 0;
            while (g < groupCount && !(groups[g].object == o && groups[g].layer == l)) ++g;
            if (g == groupCount) {
                if (groupCount == 64)
                    g = 0;
                else
                    groups[groupCount++] = {o, l, 0.0f, 0.0f, 0};
            }
            groups[g].sx += layout_.x(smp);
            groups[g].sy += layout_.y(smp);
            ++groups[g].count;
            s_.member[m] = static_cast<uint8_t>(g);
        });
        float cx[64], cy[64], best[64];
        uint32_t facet[64], pointOf[64];
        for (int g = 0; g < groupCount; ++g) {
            cx[g] = groups[g].sx / groups[g].count;
            cy[g] = groups[g].sy / groups[g].count;
            best[g] = 1e30f;
            facet[g] = 0;
        }
        forEachFragment(bx, by, x1, y1, [&](size_t smp, int l, size_t m) {
            const int g = s_.member[m];
            const float dx = layout_.x(smp) - cx[g], dy = layout_.y(smp) - cy[g];
            if (dx * dx + dy * dy < best[g]) {
                best[g] = dx * dx + dy * dy;
                facet[g] = vis_.facet[smp * layers_ + l];
            }
        });
        for (int g = 0; g < groupCount; ++g)
            pointOf[g] = add(groups[g].object, facet[g], cx[g], cy[g]);
        forEachFragment(bx, by, x1, y1, [&](size_t smp, int l, size_t m) {
            pts_.fragmentPoint[smp * layers_ + l - r_.firstSlot] = pointOf[s_.member[m]];
        });
    }

    // Groups the points by object (a counting sort); the fragments and pixels follow them.
    void sortByObject(size_t objects) {
        const size_t points = s_.unsortedObject.size();
        for (uint32_t o : s_.unsortedObject) ++pts_.objectStart[o + 1];
        sizePoints(pts_, objects);
        s_.cursor.assign(pts_.objectStart.begin(), pts_.objectStart.end() - 1);
        s_.permutation.resize(points);
        for (size_t p = 0; p < points; ++p) {
            const uint32_t at = s_.cursor[s_.unsortedObject[p]]++;
            s_.permutation[p] = at;
            pts_.object[at] = s_.unsortedObject[p];
            pts_.facet[at] = s_.unsortedFacet[p];
            pts_.x[at] = s_.unsortedX[p];
            pts_.y[at] = s_.unsortedY[p];
        }
        const size_t width = static_cast<size_t>(layout_.width());
        for (int py = r_.row0; py < r_.row1; ++py)
            for (size_t pixel = py * width + r_.col0; pixel < py * width + r_.col1; ++pixel) {
                uint32_t& whole = pts_.pixelPoint[pixel - r_.firstPixel];
                if (whole != kNoPoint) {
                    whole = s_.permutation[whole];
                    continue;
                }
                for (size_t smp = pixel * spp_; smp < (pixel + 1) * spp_; ++smp)
                    for (int l = 0; l < vis_.count[smp]; ++l) {
                        uint32_t& point = pts_.fragmentPoint[smp * layers_ + l - r_.firstSlot];
                        point = s_.permutation[point];
                    }
            }
    }

  private:
    [[gnu::always_inline]] uint32_t add(uint32_t o, uint32_t f, float x, float y) {
        s_.unsortedObject.push_back(o);
        s_.unsortedFacet.push_back(f);
        s_.unsortedX.push_back(x);
        s_.unsortedY.push_back(y);
        return static_cast<uint32_t>(s_.unsortedObject.size() - 1);
    }
    size_t pixelAt(int px, int py) const {
        return static_cast<size_t>(py - r_.row0) * static_cast<size_t>(layout_.width()) +
               static_cast<size_t>(px);
    }
    // Calls f(sample, layer, member index) for every fragment of the block.
    template <typename F>
    void forEachFragment(int bx, int by, int x1, int y1, F&& f) const {
        for (int py = by; py < y1; ++py)
            for (int px = bx; px < x1; ++px) {
                const size_t first = layout_.index(px, py, 0);
                const size_t m0 = static_cast<size_t>((py - by) * block_ + (px - bx)) * pixelSlots_;
                for (int k = 0; k < spp_; ++k)
                    for (int l = 0; l < vis_.count[first + k]; ++l)
                        f(first + k, l, m0 + static_cast<size_t>(k * layers_ + l));
            }
    }

    const SampleLayout& layout_;
    const VisibilityBuffer& vis_;
    const BandRange& r_;
    const int block_, layers_, spp_;
    const size_t pixelSlots_;
    BandPoints& pts_;
    BandPointScratch& s_;
};

}  // namespace

void buildBandPoints(const SampleLayout& layout, const VisibilityBuffer& vis,
                     const BandRange& range, size_t objects, const BandPointOptions& options,
                     BandPoints& pts, BandPointScratch& scratch) {
    pts.fragmentPoint.resize((range.endSample - range.firstSample) *
                             static_cast<size_t>(vis.layers));
    pts.objectStart.assign(objects + 1, 0);
    if (options.rate == ShadingRate::Sample) {
        if (vis.layers == 1)
            samplePointsOneLayer(layout, vis, range, objects, pts, scratch);
        else
            samplePoints(layout, vis, range, objects, pts, scratch);
    } else {
        const int block = options.rate == ShadingRate::Quad ? 2 : 1;
        BlockPoints blocks(layout, vis, range, block, pts, scratch);
        for (int by = range.row0; by < range.row1; by += block)
            for (int bx = range.col0; bx < range.col1; bx += block) {
                if (block == 1 && options.wholePixelShortcut && blocks.wholePixel(bx, by)) continue;
                const int y1 = std::min(range.row1, by + block),
                          x1 = std::min(range.col1, bx + block);
                if (block == 2 && options.wholePixelShortcut && x1 - bx == 2 && y1 - by == 2 &&
                    by % 2 == 0 && bx % 2 == 0 && blocks.wholeQuad(bx, by))
                    continue;
                blocks.groupFragments(bx, by, x1, y1);
            }
        blocks.sortByObject(objects);
    }
    const size_t points = pts.object.size();
    // One float beyond the last point's: the composite reads a point's three as four.
    pts.color.resize(3 * points + 1);
    pts.opacity.resize(3 * points + 1);
    pts.pending.clear();
    pts.fresh = true;
    pts.built = true;
}

}  // namespace mpshade
