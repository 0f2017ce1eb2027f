#include "phases/facet_rasterizer.h"

#include <algorithm>
#include <cmath>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "phases/sample_depth_test.h"
#include "phases/small_facet_depth_test.h"
#include "phases/work_deadline.h"

namespace mpshade {

void VisibilityBuffer::resize(int w, int h, int samplesPerPixel, int k) {
    width = w;
    height = h;
    spp = samplesPerPixel;
    layers = k;
    const size_t n = static_cast<size_t>(w) * h * samplesPerPixel;
    count.resize(n);
    invDepth.resize(n * static_cast<size_t>(k));
    object.resize(n * static_cast<size_t>(k));
    facet.resize(n * static_cast<size_t>(k));
}

namespace {

constexpr int kSub = FixedPointWarp::kSubpixelBits;

// A binned facet: the facet, and which of its clipped triangles (-1: the facet itself).
struct Item {
    uint32_t facet;
    int32_t clip;
};

// A fixed run of one object's facets, binned by one task into bins of its own, so the
// facet order within a tile, and the image, do not depend on scheduling.
struct Chunk {
    uint32_t object = 0;
    size_t begin = 0, end = 0;                // facets
    size_t clusterBegin = 0, clusterEnd = 0;  // clusters covering them (empty: none)
    std::vector<uint32_t> entryTile;
    std::vector<Item> entries, sorted;  // in facet order; by tile, facet order within
    std::vector<uint32_t> tileStart;    // tiles + 1 offsets into sorted
    std::vector<ScreenTriangle> clipped;
    RasterStats stats;
    int64_t longestEdge2 = 0;  // squared, in (1/256 pixel)^2
};

inline int64_t signedArea(const ScreenTriangle& t) {
    return int64_t(t.x[1] - t.x[0]) * (t.y[2] - t.y[0]) -
           int64_t(t.y[1] - t.y[0]) * (t.x[2] - t.x[0]);
}

inline ScreenTriangle screenTriangle(const WarpedVertices& w, const uint32_t* p) {
    ScreenTriangle t;
    for (int i = 0; i < 3; ++i) {
        t.x[i] = w.x[p[i]];
        t.y[i] = w.y[p[i]];
        t.invDepth[i] = w.invDepth[p[i]];
    }
    return t;
}

// Per thread: one tile's samples, `layers` slots each, local while the tile is drawn.
struct TileScratch {
    std::vector<float> inv;
    std::vector<uint32_t> object, facet;
    std::vector<uint8_t> count;
    void prepare(size_t samples, int layers, float farInv) {
        const size_t n = samples * static_cast<size_t>(layers);
        inv.assign(n, farInv);
        object.assign(n, 0);
        facet.assign(n, 0);
        count.assign(samples, 0);
    }
};

// Inserts a surface into a sample's k-buffer (nearest first), cut short behind an opaque one.
void insertLayer(TileScratch& t, size_t sample, int layers, float z, uint32_t o, uint32_t f,
                 bool opaque, const std::vector<uint8_t>& objectOpaque, RasterStats& stats) {
    float* inv = &t.inv[sample * static_cast<size_t>(layers)];
    uint32_t* obj = &t.object[sample * static_cast<size_t>(layers)];
    uint32_t* fac = &t.facet[sample * static_cast<size_t>(layers)];
    uint8_t& n = t.count[sample];
    int pos = 0;
    while (pos < n && inv[pos] >= z) {
        if (objectOpaque[obj[pos]]) return;  // hidden behind an opaque surface
        ++pos;
    }
    if (pos >= layers) {
        ++stats.droppedLayers;
        return;
    }
    const int keep = opaque ? pos : std::min<int>(n, layers - 1);
    if (!opaque && n == layers) ++stats.droppedLayers;
    for (int k = keep; k > pos; --k) {
        inv[k] = inv[k - 1];
        obj[k] = obj[k - 1];
        fac[k] = fac[k - 1];
    }
    inv[pos] = z;
    obj[pos] = o;
    fac[pos] = f;
    n = static_cast<uint8_t>(opaque ? pos + 1 : keep + 1);
}

// The frame's tiles and depth range, as both passes see them.
struct TileGrid {
    int width = 0, height = 0, spp = 0, layers = 1, tile = 1, tilesX = 0, tilesY = 0;
    size_t tileCount = 0;
    float farInv = 0.0f;  // 1 / the far plane's depth: nearer surfaces have a larger 1/z
};

// The objects' facets as chunks of whole clusters, so a culled cluster is skipped in one
// step. Reuses `chunks`; returns how many are in use.
size_t makeChunks(const std::vector<RasterObject>& objects, std::vector<Chunk>& chunks) {
    // Chunks are binned in parallel, one task each: at 32768 facets an object of the
    // teapot's size (27 800) was one chunk, binned on one thread whatever the cores (1.15 ms
    // a frame on two threads; at 4096, 0.63 ms; the vase 0.35 -> 0.23 ms). The tile pass
    // reads every chunk's bins for each tile, a few loads a chunk.
    constexpr size_t kFacetsPerChunk = 1 << 12;
    size_t count = 0;
    auto add = [&](uint32_t o, size_t begin, size_t end, size_t cb, size_t ce) {
        if (count == chunks.size()) chunks.emplace_back();
        Chunk& c = chunks[count++];
        c.object = o, c.begin = begin, c.end = end, c.clusterBegin = cb, c.clusterEnd = ce;
    };
    for (uint32_t o = 0; o < objects.size(); ++o) {
        if (!objects[o].mesh) continue;
        const FacetMesh& mesh = *objects[o].mesh;
        if (mesh.clusters.empty()) {
            for (size_t f = 0; f < mesh.facetCount(); f += kFacetsPerChunk)
                add(o, f, std::min(f + kFacetsPerChunk, mesh.facetCount()), 0, 0);
            continue;
        }
        size_t first = 0;
        while (first < mesh.clusters.size()) {
            size_t last = first, facets = 0;
            while (last < mesh.clusters.size() &&
                   (last == first || facets + mesh.clusters[last].facetCount <= kFacetsPerChunk))
                facets += mesh.clusters[last++].facetCount;
            add(o, mesh.clusters[first].firstFacet, mesh.clusters[first].firstFacet + facets, first,
                last);
            first = last;
        }
    }
    return count;
}

// Pass 1: a chunk's facets binned to the tiles their boxes touch (facets crossing the near
// plane or the guard band clipped first), then sorted by tile.
class ChunkBinner {
  public:
    ChunkBinner(Chunk& c, const RasterObject& obj, const TileGrid& grid)
        : c_(c), obj_(obj), mesh_(*obj.mesh), w_(*obj.warped), grid_(grid) {}

    void bin(WorkDeadline& deadline) {
        c_.entries.clear();
        c_.entryTile.clear();
        c_.clipped.clear();
        c_.stats = RasterStats{};
        c_.longestEdge2 = 0;
        if (deadline.passed()) {
            c_.tileStart.assign(grid_.tileCount + 1, 0);
            return;
        }
        c_.stats.facets = c_.end - c_.begin;
        const uint8_t* visible = obj_.clusterVisible;
        if (c_.clusterEnd > c_.clusterBegin) {
            for (size_t k = c_.clusterBegin; k < c_.clusterEnd; ++k) {
                const FacetCluster& cluster = mesh_.clusters[k];
                if (visible && !visible[k]) {
                    c_.stats.facetsInCulledClusters += cluster.facetCount;
                    continue;
                }
                for (size_t f = cluster.firstFacet; f < cluster.firstFacet + cluster.facetCount;
                     ++f)
                    binFacet(f);
            }
        } else {
            for (size_t f = c_.begin; f < c_.end; ++f) binFacet(f);
        }
        sortByTile();
    }

  private:
    void binFacet(size_t f) {
        const uint32_t* p = &mesh_.positionIndex[3 * f];
        if (!(w_.culled(p[0]) || w_.culled(p[1]) || w_.culled(p[2]))) {
            const ScreenTriangle t = screenTriangle(w_, p);
            if (obj_.longestEdgePixels)
                for (int i = 0; i < 3; ++i) {
                    const int64_t dx = t.x[(i + 1) % 3] - t.x[i], dy = t.y[(i + 1) % 3] - t.y[i];
                    c_.longestEdge2 = std::max(c_.longestEdge2, dx * dx + dy * dy);
                }
            binTriangle(t, static_cast<uint32_t>(f), -1);
            return;
        }
        ScreenTriangle pieces[6];
        const int n = obj_.warp ? clipFacet(*obj_.warp, mesh_, w_, p, pieces) : 0;
        if (n == 0) {
            ++c_.stats.facetsCulled;
            return;
        }
        ++c_.stats.facetsClipped;
        for (int k = 0; k < n; ++k) {
            const int32_t index = static_cast<int32_t>(c_.clipped.size());
            c_.clipped.push_back(pieces[k]);
            binTriangle(pieces[k], static_cast<uint32_t>(f), index);
        }
    }

    void binTriangle(const ScreenTriangle& t, uint32_t f, int32_t clip) {
        const int64_t area = signedArea(t);
        if (area == 0) {
            ++c_.stats.facetsDegenerate;
            return;
        }
        // Facets wind counter-clockwise about their normal; the screen's y points down, so a
        // facet seen from the front has negative area here.
        if (obj_.cullBackFaces && area > 0) {
            ++c_.stats.facetsBackFacing;
            return;
        }
        const int32_t minX = std::min({t.x[0], t.x[1], t.x[2]}),
                      maxX = std::max({t.x[0], t.x[1], t.x[2]});
        const int32_t minY = std::min({t.y[0], t.y[1], t.y[2]}),
                      maxY = std::max({t.y[0], t.y[1], t.y[2]});
        const int x0 = std::max(0, minX >> kSub), y0 = std::max(0, minY >> kSub);
        const int x1 = std::min(grid_.width - 1, maxX >> kSub),
                  y1 = std::min(grid_.height - 1, maxY >> kSub);
        if (x0 > x1 || y0 > y1) return;
        for (int ty = y0 / grid_.tile; ty <= y1 / grid_.tile; ++ty)
            for (int tx = x0 / grid_.tile; tx <= x1 / grid_.tile; ++tx) {
                c_.entryTile.push_back(static_cast<uint32_t>(ty * grid_.tilesX + tx));
                c_.entries.push_back({f, clip});
            }
    }

    // Counting sort by tile, stable: facet order within each tile.
    void sortByTile() {
        const size_t tileCount = grid_.tileCount;
        c_.tileStart.assign(tileCount + 1, 0);
        for (uint32_t t : c_.entryTile) ++c_.tileStart[t + 1];
        for (size_t t = 0; t < tileCount; ++t) c_.tileStart[t + 1] += c_.tileStart[t];
        c_.sorted.resize(c_.entries.size());
        std::vector<uint32_t>& next = c_.entryTile;  // reused: entries' tiles become cursors
        for (size_t e = 0; e < c_.entries.size(); ++e) {
            const uint32_t t = next[e];
            c_.sorted[c_.tileStart[t]++] = c_.entries[e];
        }
        for (size_t t = tileCount; t > 0; --t) c_.tileStart[t] = c_.tileStart[t - 1];
        c_.tileStart[0] = 0;
    }

    Chunk& c_;
    const RasterObject& obj_;
    const FacetMesh& mesh_;
    const WarpedVertices& w_;
    const TileGrid& grid_;
};

// Pass 2: one tile, every chunk's facets binned to it in order, depth-tested into the
// frame's buffer (one layer: directly, a tile's row of samples being contiguous there) or
// into a tile-local k-buffer copied out at the end (several layers).
class TileRasterizer {
  public:
    TileRasterizer(size_t t, const TileGrid& grid, const SampleLayout& samples,
                   VisibilityBuffer& out, TileScratch& scratch, RasterStats& stats)
        : grid_(grid),
          samples_(samples),
          out_(out),
          scratch_(scratch),
          s_(stats),
          fx_(samples.fixedX()),
          fy_(samples.fixedY()),
          tx0_(static_cast<int>(t % grid.tilesX) * grid.tile),
          ty0_(static_cast<int>(t / grid.tilesX) * grid.tile),
          tx1_(std::min(grid.width, tx0_ + grid.tile) - 1),
          ty1_(std::min(grid.height, ty0_ + grid.tile) - 1),
          rowSamples_(static_cast<size_t>(tx1_ - tx0_ + 1) * grid.spp),
          direct_(grid.layers == 1),
          ox_(tx0_ << kSub),
          oy_(ty0_ << kSub),
          cornerX_{0.0, static_cast<double>((tx1_ - tx0_ + 1) << kSub)},
          cornerY_{0.0, static_cast<double>((ty1_ - ty0_ + 1) << kSub)} {}

    void clear() {
        if (!direct_) {
            scratch_.prepare(rowSamples_ * static_cast<size_t>(ty1_ - ty0_ + 1), grid_.layers,
                             grid_.farInv);
            return;
        }
        for (int py = ty0_; py <= ty1_; ++py) {
            const size_t g = samples_.index(tx0_, py, 0);
            // The tile's samples and ids, asked for now rather than by whichever facet first
            // reaches each line: a steady frame's visibility buffer is not in cache, and
            // small facets' boxes gave the hardware prefetcher no run to follow.
            // Rasterizing took 2-14% less (courtyard, gallery, teapot at 640x360).
            for (size_t b = 0; b < rowSamples_; b += 16) {
                __builtin_prefetch(fx_ + g + b);
                __builtin_prefetch(fy_ + g + b);
                __builtin_prefetch(&out_.object[g + b], 1);
                __builtin_prefetch(&out_.facet[g + b], 1);
            }
            std::fill_n(&out_.invDepth[g], rowSamples_, grid_.farInv);
        }
    }

    void draw(const ScreenTriangle& tri, uint32_t object, uint32_t facet, bool opaque,
              const std::vector<uint8_t>& objectOpaque) {
        const int32_t minX = std::min({tri.x[0], tri.x[1], tri.x[2]}),
                      maxX = std::max({tri.x[0], tri.x[1], tri.x[2]});
        const int32_t minY = std::min({tri.y[0], tri.y[1], tri.y[2]}),
                      maxY = std::max({tri.y[0], tri.y[1], tri.y[2]});
        const int px0 = minX >> kSub, px1 = maxX >> kSub, py0 = minY >> kSub, py1 = maxY >> kSub;
        if (px1 - px0 < kSmallFacetPixels && py1 - py0 < kSmallFacetPixels) {
            drawSmall(tri, px0, py0, px1, py1, object, facet, opaque, objectOpaque);
            return;
        }
        FacetEdges su;
        setUpFacetEdges<int64_t>(tri.x, tri.y, tri.invDepth, ox_, oy_, su);
        // The edges at the tile's corners: all inside, the tile is covered whole; one wholly
        // outside, nothing to do. A facet whose box leaves out a corner of the tile covers
        // neither, and its box within the tile is what the samples are tested in anyway: the
        // twelve edge evaluations are for facets as large as the tile (most facets are a
        // pixel or two across).
        bool whole = false, outside = false;
        const int64_t tileX1 = ox_ + static_cast<int64_t>(cornerX_[1]),
                      tileY1 = oy_ + static_cast<int64_t>(cornerY_[1]);
        if (minX <= ox_ && minY <= oy_ && maxX >= tileX1 && maxY >= tileY1) {
            whole = true;
            for (int i = 0; i < 3; ++i) {
                double lo = 1e300, hi = -1e300;
                for (double cy : cornerY_)
                    for (double cx : cornerX_) {
                        const double edge = su.c[i] + su.a[i] * cx + su.b[i] * cy;
                        lo = std::min(lo, edge);
                        hi = std::max(hi, edge);
                    }
                whole = whole && lo > 0.0;
                outside = outside || hi <= 0.0;
            }
        }
        if (outside) return;
        ++s_.facetsBinned;
        s_.tilesCoveredWhole += whole;
        const int bx0 = std::max(tx0_, minX >> kSub), by0 = std::max(ty0_, minY >> kSub);
        const int bx1 = std::min(tx1_, maxX >> kSub), by1 = std::min(ty1_, maxY >> kSub);
        if (direct_) {
            s_.fragments += depthTestRows(frameRows(bx0, by0, bx1, by1),
                                          {&su, ox_, oy_, !whole, object, facet});
            return;
        }
        drawLayers(bx0, by0, bx1, by1, object, facet, opaque, objectOpaque,
                   [&](int32_t x, int32_t y, float& z) {
                       const double lx = x - ox_, ly = y - oy_;
                       bool in = true;
                       for (int k = 0; k < 3; ++k)
                           in = in && su.c[k] + su.a[k] * lx + su.b[k] * ly > 0.0;
                       z = static_cast<float>(su.zc + su.zx * lx + su.zy * ly);
                       return in;
                   });
    }

    // Into the tile's k-buffer: the samples of pixels [bx0, bx1] x [by0, by1] of the tile
    // that inside(x, y, z) says are in the facet (setting z, their 1 / depth).
    template <typename Inside>
    void drawLayers(int bx0, int by0, int bx1, int by1, uint32_t object, uint32_t facet,
                    bool opaque, const std::vector<uint8_t>& objectOpaque, Inside&& inside) {
        const size_t spp = static_cast<size_t>(grid_.spp);
        for (int py = by0; py <= by1; ++py) {
            const size_t g = samples_.index(bx0, py, 0);
            const size_t n = static_cast<size_t>(bx1 - bx0 + 1) * spp;
            const size_t l = static_cast<size_t>(py - ty0_) * rowSamples_ +
                             static_cast<size_t>(bx0 - tx0_) * spp;
            for (size_t i = 0; i < n; ++i) {
                float z;
                if (!inside(fx_[g + i], fy_[g + i], z) || !(z > grid_.farInv)) continue;
                ++s_.fragments;
                insertLayer(scratch_, l + i, grid_.layers, z, object, facet, opaque, objectOpaque,
                            s_);
            }
        }
    }

    // A facet whose box of pixels is at most kSmallFacetPixels on a side, in float lanes
    // relative to the box's corner (small_facet_depth_test.h). Its box is smaller than a
    // tile, so the corner tests for covering a tile whole are skipped.
    void drawSmall(const ScreenTriangle& tri, int px0, int py0, int px1, int py1, uint32_t object,
                   uint32_t facet, bool opaque, const std::vector<uint8_t>& objectOpaque) {
        const int32_t ox = px0 * (1 << kSub), oy = py0 * (1 << kSub);
        const SmallFacetEdges edges = smallFacetEdges(tri.x, tri.y, tri.invDepth, ox, oy);
        const int bx0 = std::max(tx0_, px0), by0 = std::max(ty0_, py0);
        const int bx1 = std::min(tx1_, px1), by1 = std::min(ty1_, py1);
        if (bx0 > bx1 || by0 > by1) return;
        ++s_.facetsBinned;
        if (!direct_) {
            drawLayers(bx0, by0, bx1, by1, object, facet, opaque, objectOpaque,
                       [&](int32_t x, int32_t y, float& z) {
                           const float lx = static_cast<float>(x - ox),
                                       ly = static_cast<float>(y - oy);
                           z = smallFacetDepth(edges, lx, ly);
                           return smallFacetInside(edges, lx, ly);
                       });
            return;
        }
        s_.fragments += smallFacetDepthTest(frameRows(bx0, by0, bx1, by1), edges, object, facet);
    }

    // The frame buffer's samples of pixels [bx0, bx1] x [by0, by1] (one layer), row by row.
    SampleRows frameRows(int bx0, int by0, int bx1, int by1) const {
        const size_t g = samples_.index(bx0, by0, 0);
        const size_t spp = static_cast<size_t>(grid_.spp);
        return {fx_ + g,
                fy_ + g,
                &out_.invDepth[g],
                &out_.object[g],
                &out_.facet[g],
                static_cast<size_t>(by1 - by0 + 1),
                static_cast<size_t>(bx1 - bx0 + 1) * spp,
                static_cast<size_t>(grid_.width) * spp};
    }

    // Out to the frame's buffer, row by row: the sample counts (one layer), or the k-buffer.
    void finish() {
        const size_t layers = static_cast<size_t>(grid_.layers);
        for (int py = ty0_; py <= ty1_; ++py) {
            const size_t g = samples_.index(tx0_, py, 0);
            if (direct_) {
                const float* __restrict inv = &out_.invDepth[g];
                uint8_t* __restrict count = &out_.count[g];
                for (size_t i = 0; i < rowSamples_; ++i) count[i] = inv[i] > grid_.farInv ? 1 : 0;
                continue;
            }
            const size_t l = static_cast<size_t>(py - ty0_) * rowSamples_;
            const size_t gl = g * layers, ll = l * layers, nl = rowSamples_ * layers;
            std::copy_n(&scratch_.inv[ll], nl, &out_.invDepth[gl]);
            std::copy_n(&scratch_.object[ll], nl, &out_.object[gl]);
            std::copy_n(&scratch_.facet[ll], nl, &out_.facet[gl]);
            std::copy_n(&scratch_.count[l], rowSamples_, &out_.count[g]);
        }
    }

  private:
    const TileGrid& grid_;
    const SampleLayout& samples_;
    VisibilityBuffer& out_;
    TileScratch& scratch_;
    RasterStats& s_;
    const int32_t* fx_;
    const int32_t* fy_;
    const int tx0_, ty0_, tx1_, ty1_;
    const size_t rowSamples_;
    const bool direct_;
    const int32_t ox_, oy_;
    const double cornerX_[2], cornerY_[2];
};

}  // namespace

struct FacetRasterizer::State {
    std::vector<Chunk> chunks;
    tbb::enumerable_thread_specific<TileScratch> scratch;
    tbb::enumerable_thread_specific<RasterStats> tileStats;
    std::vector<uint8_t> objectOpaque;
};

FacetRasterizer::FacetRasterizer() : state_(std::make_unique<State>()) {}
FacetRasterizer::~FacetRasterizer() = default;

void FacetRasterizer::rasterize(const std::vector<RasterObject>& objects,
                                const SampleLayout& samples, float farDepth,
                                const RasterOptions& options, VisibilityBuffer& out,
                                RasterStats& stats) {
    State& st = *state_;
    bool allOpaque = true;
    st.objectOpaque.resize(objects.size());
    for (size_t o = 0; o < objects.size(); ++o) {
        st.objectOpaque[o] = objects[o].opaque ? 1 : 0;
        allOpaque = allOpaque && objects[o].opaque;
    }
    TileGrid grid;
    grid.width = samples.width(), grid.height = samples.height(), grid.spp = samples.spp();
    grid.layers = allOpaque ? 1 : std::clamp(options.layers, 1, 255);
    out.resize(grid.width, grid.height, grid.spp, grid.layers);
    grid.tile = std::clamp(options.tileSize, 1, 256);
    grid.tilesX = (grid.width + grid.tile - 1) / grid.tile;
    grid.tilesY = (grid.height + grid.tile - 1) / grid.tile;
    grid.tileCount = static_cast<size_t>(grid.tilesX) * grid.tilesY;
    grid.farInv = farDepth > 0.0f && std::isfinite(farDepth) ? 1.0f / farDepth : 0.0f;
    const size_t chunkCount = makeChunks(objects, st.chunks);

    // Checked once per chunk and per tile: a clock read costs far less than either.
    WorkDeadline deadline(options.deadline);
    tbb::parallel_for(size_t{0}, chunkCount, [&](size_t ci) {
        Chunk& c = st.chunks[ci];
        ChunkBinner(c, objects[c.object], grid).bin(deadline);
    });
    for (RasterStats& s : st.tileStats) s = RasterStats{};
    tbb::parallel_for(size_t{0}, deadline.passed() ? size_t{0} : grid.tileCount, [&](size_t t) {
        if (deadline.passed()) return;
        TileRasterizer tile(t, grid, samples, out, st.scratch.local(), st.tileStats.local());
        tile.clear();
        for (size_t ci = 0; ci < chunkCount; ++ci) {
            const Chunk& c = st.chunks[ci];
            const RasterObject& obj = objects[c.object];
            for (uint32_t e = c.tileStart[t]; e < c.tileStart[t + 1]; ++e) {
                const Item& item = c.sorted[e];
                const ScreenTriangle tri =
                    item.clip >= 0
                        ? c.clipped[static_cast<size_t>(item.clip)]
                        : screenTriangle(*obj.warped,
                                         &obj.mesh->positionIndex[3 * size_t{item.facet}]);
                tile.draw(tri, c.object, item.facet, obj.opaque, st.objectOpaque);
            }
        }
        tile.finish();
    });

    stats = RasterStats{};
    stats.abandoned = deadline.missed();
    for (const RasterObject& obj : objects)
        if (obj.longestEdgePixels) *obj.longestEdgePixels = 0.0f;
    for (size_t ci = 0; ci < chunkCount; ++ci) {
        if (float* longest = objects[st.chunks[ci].object].longestEdgePixels)
            *longest = std::max(
                *longest,
                static_cast<float>(std::sqrt(static_cast<double>(st.chunks[ci].longestEdge2))) /
                    256.0f);
        stats += st.chunks[ci].stats;
    }
    for (const RasterStats& s : st.tileStats) stats += s;
}

void rasterizeFacets(const std::vector<RasterObject>& objects, const SampleLayout& samples,
                     float farDepth, const RasterOptions& options, VisibilityBuffer& out,
                     RasterStats& stats) {
    FacetRasterizer rasterizer;
    rasterizer.rasterize(objects, samples, farDepth, options, out, stats);
}

}  // namespace mpshade
