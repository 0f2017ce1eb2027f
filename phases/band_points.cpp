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
// The row's bounds are taken before its loop: f stores through pointers the compiler cannot
// tell from the layout's, and it had computed the end again for every sample.
template <typename F>
void forEachCoveredSample(const SampleLayout& layout, const BandRange& r, const uint8_t* count,
                          F&& f) {
    for (int py = r.row0; py < r.row1; ++py) {
        const size_t end = layout.index(r.col1, py, 0);
        for (size_t smp = layout.index(r.col0, py, 0); smp < end; ++smp)
            if (count[smp]) f(smp);
    }
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
    const size_t firstSlot = r.firstSlot;  // the first sample's (one layer)
    const float* const xy = layout.positions();
    current = kNone;
    uint32_t at = 0;
    forEachCoveredSample(layout, r, count, [&](size_t smp) {
        if (object[smp] != current) {
            if (current != kNone) s.cursor[current] = at;
            current = object[smp], at = s.cursor[current];
        }
        pointObject[at] = current;
        pointFacet[at] = facet[smp];
        pointX[at] = xy[2 * smp];
        pointY[at] = xy[2 * smp + 1];
        fragmentPoint[smp - firstSlot] = at++;
    });
}

// Per sample: a point per fragment, placed by object as it is made (a counting sort).
void samplePoints(const SampleLayout& layout, const VisibilityBuffer& vis, const BandRange& r,
                  size_t objects, BandPoints& pts, BandPointScratch& s) {
    const int layers = vis.layers;
    pts.pixelPoint.clear();
    forEachCoveredSample(layout, r, vis.count.data(), [&](size_t smp) {
        for (int l = 0; l < vis.count[smp]; ++l)
            ++pts.objectStart[vis.object[smp * layers + l] + 1];
    });
    sizePoints(pts, objects);
    s.cursor.assign(pts.objectStart.begin(), pts.objectStart.end() - 1);
    const float* const xy = layout.positions();
    forEachCoveredSample(layout, r, vis.count.data(), [&](size_t smp) {
        for (int l = 0; l < vis.count[smp]; ++l) {
            const size_t slot = smp * layers + l;
            const uint32_t o = vis.object[slot];
            const uint32_t at = s.cursor[o]++;
            pts.object[at] = o;
            pts.facet[at] = vis.facet[slot];
            pts.x[at] = xy[2 * smp];
            pts.y[at] = xy[2 * smp + 1];
            pts.fragmentPoint[slot - r.firstSlot] = at;
        }
    });
}

// Per pixel or per block of 2x2 pixels, in two passes over the blocks. The first finds
// each block's surface where one surface covers it whole (most blocks), groups the others'
// fragments (groupFragments), and counts the points of each object; the second writes each
// point straight to its place in its object's run. Grouping by object after the fact (a
// third array set and a permutation applied to every pixel) took twice as long.
class BlockPoints {
  public:
    BlockPoints(const SampleLayout& layout, const VisibilityBuffer& vis, const BandRange& r,
                int block, bool shortcut, BandPoints& pts, BandPointScratch& s)
        : layout_(layout),
          vis_(vis),
          r_(r),
          block_(block),
          layers_(vis.layers),
          spp_(layout.spp()),
          shortcut_(shortcut),
          pixelSlots_(static_cast<size_t>(layout.spp()) * vis.layers),
          pts_(pts),
          s_(s) {
        s.unsortedObject.clear(), s.unsortedFacet.clear();
        s.unsortedX.clear(), s.unsortedY.clear();
        s.blockObject.clear(), s.groupEnd.clear();
        // Every pixel of the range is written by place(); the others are never read.
        pts.pixelPoint.resize(static_cast<size_t>(r.row1 - r.row0) *
                              static_cast<size_t>(layout.width()));
        s.member.resize(static_cast<size_t>(block * block) * pixelSlots_);
    }

    // Pass 1: per block its object if one surface covers it whole, kEmpty if nothing does,
    // else kMixed and its groups made; the points of each object counted in
    // objectStart[o + 1].
    void classify() {
        uint32_t current = kMixed, run = 0;  // a run of whole blocks of one object
        forEachBlock([&](int bx, int by, int x1, int y1) {
            const uint32_t o = blockState(bx, by, x1, y1);
            s_.blockObject.push_back(o);
            if (o == kEmpty) return;
            if (o == kMixed) {
                groupFragments(bx, by, x1, y1);
                s_.groupEnd.push_back(static_cast<uint32_t>(s_.unsortedObject.size()));
                return;
            }
            if (o != current) {
                if (current != kMixed) pts_.objectStart[current + 1] += run;
                current = o, run = 0;
            }
            ++run;
        });
        if (current != kMixed) pts_.objectStart[current + 1] += run;
    }

    // Pass 2: every point written at its place, pixels and fragments pointing at it.
    void place(size_t objects) {
        sizePoints(pts_, objects);
        s_.cursor.assign(pts_.objectStart.begin(), pts_.objectStart.end() - 1);
        s_.permutation.resize(s_.unsortedObject.size());
        size_t b = 0, mixed = 0;
        uint32_t group = 0;
        uint32_t current = kMixed, at = 0;  // the cursor of a run of whole blocks, in a register
        forEachBlock([&](int bx, int by, int x1, int y1) {
            const uint32_t o = s_.blockObject[b++];
            if (o == kEmpty) {
                for (int py = by; py < y1; ++py)
                    for (int px = bx; px < x1; ++px) pts_.pixelPoint[pixelAt(px, py)] = kNoPoint;
                return;
            }
            if (o != kMixed) {
                if (o != current) {
                    if (current != kMixed) s_.cursor[current] = at;
                    current = o, at = s_.cursor[o];
                }
                if (block_ == 1)
                    placeWholePixel(bx, by, o, at++);
                else
                    placeWholeQuad(bx, by, o, at++);
                return;
            }
            if (current != kMixed) s_.cursor[current] = at, current = kMixed;
            const uint32_t end = s_.groupEnd[mixed++];
            for (; group < end; ++group) {
                const uint32_t to = s_.cursor[s_.unsortedObject[group]]++;
                s_.permutation[group] = to;
                write(to, s_.unsortedObject[group], s_.unsortedFacet[group], s_.unsortedX[group],
                      s_.unsortedY[group]);
            }
            for (int py = by; py < y1; ++py)
                for (int px = bx; px < x1; ++px) pts_.pixelPoint[pixelAt(px, py)] = kNoPoint;
            forEachFragment(bx, by, x1, y1, [&](size_t smp, int l, size_t) {
                uint32_t& point = pts_.fragmentPoint[smp * layers_ + l - r_.firstSlot];
                point = s_.permutation[point];
            });
        });
    }

  private:
    // Block states besides an object's index: several surfaces, or none at all.
    static constexpr uint32_t kMixed = ~uint32_t{0}, kEmpty = ~uint32_t{0} - 1;

    // Calls f(bx, by, x1, y1) for every block of the range, in order: rows of blocks, then
    // columns; blocks at the range's right or bottom edge may be cut short.
    template <typename F>
    void forEachBlock(F&& f) const {
        for (int by = r_.row0; by < r_.row1; by += block_) {
            const int y1 = std::min(r_.row1, by + block_);
            for (int bx = r_.col0; bx < r_.col1; bx += block_)
                f(bx, by, std::min(r_.col1, bx + block_), y1);
        }
    }

    // The pixel's state: the object of the one surface covering every sample in front,
    // kEmpty if no sample sees anything, else kMixed.
    uint32_t pixelState(int px, int py) const {
        const size_t first = layout_.index(px, py, 0);
        const uint8_t* count = vis_.count.data() + first;
        if (count[0] == 0) {
            for (int k = 1; k < spp_; ++k)
                if (count[k] != 0) return kMixed;
            return kEmpty;
        }
        if (count[0] != 1) return kMixed;
        const uint32_t o = vis_.object[first * layers_];
        for (int k = 1; k < spp_; ++k)
            if (count[k] != 1 || vis_.object[(first + k) * layers_] != o) return kMixed;
        return o;
    }

    // The block's state. A whole pixel, or a whole 2x2 block at even coordinates (inside
    // the image), takes its point from the layout's precomputed centroid and nearest sample
    // (placeWholePixel, placeWholeQuad): what groupFragments finds, without grouping.
    uint32_t blockState(int bx, int by, int x1, int y1) const {
        uint32_t state;
        if (block_ == 1) {
            state = pixelState(bx, by);
        } else if (x1 - bx == 2 && y1 - by == 2 && by % 2 == 0 && bx % 2 == 0) {
            state = pixelState(bx, by);
            if (state == kMixed || pixelState(bx + 1, by) != state ||
                pixelState(bx, by + 1) != state || pixelState(bx + 1, by + 1) != state)
                return kMixed;
        } else {
            for (int py = by; py < y1; ++py)
                for (int px = bx; px < x1; ++px)
                    if (pixelState(px, py) != kEmpty) return kMixed;
            return kEmpty;
        }
        return shortcut_ || state == kEmpty ? state : kMixed;
    }

    void placeWholePixel(int bx, int by, uint32_t o, uint32_t at) {
        // Not first / spp: a 64-bit division a pixel was a tenth of this step's time.
        const size_t pixel = static_cast<size_t>(by) * static_cast<size_t>(layout_.width()) +
                             static_cast<size_t>(bx);
        const size_t nearest = layout_.index(bx, by, layout_.nearestToCentroid(pixel));
        write(at, o, vis_.facet[nearest * layers_], layout_.centroidX(pixel),
              layout_.centroidY(pixel));
        pts_.pixelPoint[pixelAt(bx, by)] = at;
    }

    void placeWholeQuad(int bx, int by, uint32_t o, uint32_t at) {
        const size_t quad = static_cast<size_t>(by / 2) * (layout_.width() / 2) + bx / 2;
        const int m = layout_.nearestToQuadCentroid(quad);
        const size_t nearest = layout_.index(bx + (m / spp_) % 2, by + m / (2 * spp_), m % spp_);
        write(at, o, vis_.facet[nearest * layers_], layout_.quadCentroidX(quad),
              layout_.quadCentroidY(quad));
        for (int dy = 0; dy < 2; ++dy)
            for (int dx = 0; dx < 2; ++dx) pts_.pixelPoint[pixelAt(bx + dx, by + dy)] = at;
    }

    // The general case: the block's fragments grouped by surface (object and layer; past 64
    // surfaces the rest merge into the first), each group's point at its centroid on the
    // facet of the member sample nearest to it. The groups go to the unsorted arrays, and
    // each fragment's point is its group's index there until place().
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
        for (int g = 0; g < groupCount; ++g) {
            pointOf[g] = static_cast<uint32_t>(s_.unsortedObject.size());
            ++pts_.objectStart[groups[g].object + 1];
            s_.unsortedObject.push_back(groups[g].object);
            s_.unsortedFacet.push_back(facet[g]);
            s_.unsortedX.push_back(cx[g]);
            s_.unsortedY.push_back(cy[g]);
        }
        forEachFragment(bx, by, x1, y1, [&](size_t smp, int l, size_t m) {
            pts_.fragmentPoint[smp * layers_ + l - r_.firstSlot] = pointOf[s_.member[m]];
        });
    }

    [[gnu::always_inline]] void write(uint32_t at, uint32_t o, uint32_t f, float x, float y) {
        pts_.object[at] = o;
        pts_.facet[at] = f;
        pts_.x[at] = x;
        pts_.y[at] = y;
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
    const bool shortcut_;
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
        BlockPoints blocks(layout, vis, range, block, options.wholePixelShortcut, pts, scratch);
        blocks.classify();
        blocks.place(objects);
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
