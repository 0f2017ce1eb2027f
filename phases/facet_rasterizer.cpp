#include "phases/facet_rasterizer.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

namespace mpshade {

void FragmentBuffer::resize(int w, int h, int samplesPerPixel, int k) {
    width = w;
    height = h;
    spp = samplesPerPixel;
    layers = k;
    const size_t n = static_cast<size_t>(w) * h * samplesPerPixel;
    fragments.resize(n * static_cast<size_t>(k));
    count.assign(n, 0);
}

namespace {

struct Binned {
    uint32_t object, facet;
};

// The tie rule: a sample exactly on edge (dx, dy) is inside for this direction and not for
// the reverse, so a shared edge's samples go to exactly one facet.
inline bool ownsEdge(int64_t dx, int64_t dy) {
    return dy > 0 || (dy == 0 && dx < 0);
}

struct PixelBox {
    int x0, y0, x1, y1;  // inclusive pixels
};

inline bool facetBox(const WarpedVertices& w, const uint32_t* p, int width, int height,
                     PixelBox& box) {
    const int32_t minX = std::min({w.x[p[0]], w.x[p[1]], w.x[p[2]]}),
                  maxX = std::max({w.x[p[0]], w.x[p[1]], w.x[p[2]]});
    const int32_t minY = std::min({w.y[p[0]], w.y[p[1]], w.y[p[2]]}),
                  maxY = std::max({w.y[p[0]], w.y[p[1]], w.y[p[2]]});
    box.x0 = std::max(0, minX >> FixedPointWarp::kSubpixelBits);
    box.y0 = std::max(0, minY >> FixedPointWarp::kSubpixelBits);
    box.x1 = std::min(width - 1, maxX >> FixedPointWarp::kSubpixelBits);
    box.y1 = std::min(height - 1, maxY >> FixedPointWarp::kSubpixelBits);
    return box.x0 <= box.x1 && box.y0 <= box.y1;
}

void insertFragment(FragmentBuffer& out, size_t sample, const Fragment& f, RasterStats& stats) {
    Fragment* list = &out.fragments[sample * static_cast<size_t>(out.layers)];
    uint8_t& n = out.count[sample];
    int pos = 0;
    while (pos < n && list[pos].depth <= f.depth) {
        if (list[pos].opaque) return;  // hidden behind an opaque fragment
        ++pos;
    }
    if (pos >= out.layers) {
        ++stats.droppedLayers;
        return;
    }
    const int keep = f.opaque ? pos : std::min<int>(n, out.layers - 1);
    if (!f.opaque && n == out.layers) ++stats.droppedLayers;
    for (int k = keep; k > pos; --k) list[k] = list[k - 1];
    list[pos] = f;
    n = static_cast<uint8_t>(f.opaque ? pos + 1 : keep + 1);
}

}  // namespace

void rasterizeFacets(const std::vector<RasterObject>& objects, const SampleBuffer& samples,
                     const RasterOptions& options, FragmentBuffer& out, RasterStats& stats) {
    const int width = samples.width, height = samples.height, spp = samples.spp;
    out.resize(width, height, spp, options.layers);
    const int tile = std::max(1, options.tileSize);
    const int tilesX = (width + tile - 1) / tile, tilesY = (height + tile - 1) / tile;
    const size_t tileCount = static_cast<size_t>(tilesX) * tilesY;

    // Sample positions on the sub-pixel grid.
    std::vector<int32_t> sx(samples.xy.size() / 2), sy(samples.xy.size() / 2);
    for (size_t i = 0; i < sx.size(); ++i) {
        sx[i] = static_cast<int32_t>(std::lround(samples.xy[2 * i] * 256.0f));
        sy[i] = static_cast<int32_t>(std::lround(samples.xy[2 * i + 1] * 256.0f));
    }

    // Bin facets into tiles. The facets are cut into fixed chunks, each binned by one task
    // into bins of its own (no atomics); a tile then takes the chunks' bins in chunk order,
    // so the facet order, and the image, do not depend on scheduling.
    struct FacetRange {
        uint32_t object;
        size_t begin, end;                // facets
        size_t clusterBegin, clusterEnd;  // clusters covering them (empty: none)
    };
    constexpr size_t kFacetsPerChunk = 1 << 16;
    std::vector<FacetRange> ranges;
    for (uint32_t o = 0; o < objects.size(); ++o) {
        const FacetMesh& mesh = *objects[o].mesh;
        if (mesh.clusters.empty()) {
            for (size_t f = 0; f < mesh.facetCount(); f += kFacetsPerChunk)
                ranges.push_back({o, f, std::min(f + kFacetsPerChunk, mesh.facetCount()), 0, 0});
            continue;
        }
        // Whole clusters per chunk, so a culled cluster is skipped in one step.
        size_t first = 0;
        while (first < mesh.clusters.size()) {
            size_t last = first, facets = 0;
            while (last < mesh.clusters.size() &&
                   (last == first || facets + mesh.clusters[last].facetCount <= kFacetsPerChunk))
                facets += mesh.clusters[last++].facetCount;
            ranges.push_back({o, mesh.clusters[first].firstFacet,
                              mesh.clusters[first].firstFacet + facets, first, last});
            first = last;
        }
    }
    std::vector<std::vector<std::vector<Binned>>> chunkBins(ranges.size());
    std::vector<RasterStats> chunkStats(ranges.size());
    tbb::parallel_for(size_t{0}, ranges.size(), [&](size_t c) {
        const FacetRange& range = ranges[c];
        const FacetMesh& mesh = *objects[range.object].mesh;
        const WarpedVertices& w = *objects[range.object].warped;
        auto& bins = chunkBins[c];
        bins.resize(tileCount);
        RasterStats& st = chunkStats[c];
        st.facets = range.end - range.begin;
        auto binFacet = [&](size_t f) {
            const uint32_t* p = &mesh.positionIndex[3 * f];
            if (w.culled[p[0]] | w.culled[p[1]] | w.culled[p[2]]) {
                ++st.facetsCulled;
                return;
            }
            const int64_t area = int64_t(w.x[p[1]] - w.x[p[0]]) * (w.y[p[2]] - w.y[p[0]]) -
                                 int64_t(w.y[p[1]] - w.y[p[0]]) * (w.x[p[2]] - w.x[p[0]]);
            if (area == 0) {
                ++st.facetsDegenerate;
                return;
            }
            // Facets wind counter-clockwise about their normal; the screen's y points down,
            // so a facet seen from the front has negative area here.
            if (objects[range.object].cullBackFaces && area > 0) {
                ++st.facetsBackFacing;
                return;
            }
            PixelBox box;
            if (!facetBox(w, p, width, height, box)) return;
            for (int ty = box.y0 / tile; ty <= box.y1 / tile; ++ty)
                for (int tx = box.x0 / tile; tx <= box.x1 / tile; ++tx)
                    bins[static_cast<size_t>(ty) * tilesX + tx].push_back(
                        {range.object, static_cast<uint32_t>(f)});
        };
        const uint8_t* visible = objects[range.object].clusterVisible;
        if (range.clusterEnd > range.clusterBegin) {
            for (size_t k = range.clusterBegin; k < range.clusterEnd; ++k) {
                const FacetCluster& cluster = mesh.clusters[k];
                if (visible && !visible[k]) {
                    st.facetsInCulledClusters += cluster.facetCount;
                    continue;
                }
                for (size_t f = cluster.firstFacet; f < cluster.firstFacet + cluster.facetCount;
                     ++f)
                    binFacet(f);
            }
        } else {
            for (size_t f = range.begin; f < range.end; ++f) binFacet(f);
        }
    });

    tbb::enumerable_thread_specific<RasterStats> tileStats;
    tbb::parallel_for(size_t{0}, tileCount, [&](size_t t) {
        RasterStats& st = tileStats.local();
        const int tx0 = static_cast<int>(t % tilesX) * tile,
                  ty0 = static_cast<int>(t / tilesX) * tile;
        const int tx1 = std::min(width, tx0 + tile) - 1, ty1 = std::min(height, ty0 + tile) - 1;
        for (size_t chunk = 0; chunk < chunkBins.size(); ++chunk)
            for (const Binned& bin : chunkBins[chunk][t]) {
                const RasterObject& obj = objects[bin.object];
                const WarpedVertices& w = *obj.warped;
                const uint32_t* p = &obj.mesh->positionIndex[3 * static_cast<size_t>(bin.facet)];
                int64_t x[3] = {w.x[p[0]], w.x[p[1]], w.x[p[2]]},
                        y[3] = {w.y[p[0]], w.y[p[1]], w.y[p[2]]};
                float invW[3] = {1.0f / w.depth[p[0]], 1.0f / w.depth[p[1]], 1.0f / w.depth[p[2]]};
                int64_t area = (x[1] - x[0]) * (y[2] - y[0]) - (y[1] - y[0]) * (x[2] - x[0]);
                // Positive orientation; remember which original corners 1 and 2 are.
                int c1 = 1, c2 = 2;
                if (area < 0) {
                    std::swap(x[1], x[2]);
                    std::swap(y[1], y[2]);
                    std::swap(invW[1], invW[2]);
                    std::swap(c1, c2);
                    area = -area;
                }
                ++st.facetsBinned;
                // Edge k runs from vertex k + 1 to k + 2, opposite vertex k.
                const int64_t dx[3] = {x[2] - x[1], x[0] - x[2], x[1] - x[0]};
                const int64_t dy[3] = {y[2] - y[1], y[0] - y[2], y[1] - y[0]};
                const int64_t ax[3] = {x[1], x[2], x[0]}, ay[3] = {y[1], y[2], y[0]};
                const bool owns[3] = {ownsEdge(dx[0], dy[0]), ownsEdge(dx[1], dy[1]),
                                      ownsEdge(dx[2], dy[2])};
                PixelBox box;
                facetBox(w, p, width, height, box);
                box.x0 = std::max(box.x0, tx0), box.y0 = std::max(box.y0, ty0);
                box.x1 = std::min(box.x1, tx1), box.y1 = std::min(box.y1, ty1);
                const float invArea = 1.0f / static_cast<float>(area);
                const int64_t minX = std::min({x[0], x[1], x[2]}),
                              maxX = std::max({x[0], x[1], x[2]});
                const int64_t minY = std::min({y[0], y[1], y[2]}),
                              maxY = std::max({y[0], y[1], y[2]});
                for (int py = box.y0; py <= box.y1; ++py) {
                    for (int px = box.x0; px <= box.x1; ++px) {
                        for (int k = 0; k < spp; ++k) {
                            const size_t s = samples.index(px, py, k);
                            const int64_t qx = sx[s], qy = sy[s];
                            // Most sub-pixel facets hold no sample: reject on the box first.
                            if (qx < minX || qx > maxX || qy < minY || qy > maxY) continue;
                            int64_t e[3];
                            bool inside = true;
                            for (int i = 0; i < 3; ++i) {
                                // With positive orientation, e[i] is +area at vertex i and 0
                                // on edge i: the interior has every e[i] > 0.
                                e[i] = dx[i] * (qy - ay[i]) - dy[i] * (qx - ax[i]);
                                inside = inside && (e[i] > 0 || (e[i] == 0 && owns[i]));
                            }
                            if (!inside) continue;
                            // Screen-space weights, then perspective-correct ones.
                            const float l0 = static_cast<float>(e[0]) * invArea * invW[0];
                            const float l1 = static_cast<float>(e[1]) * invArea * invW[1];
                            const float l2 = static_cast<float>(e[2]) * invArea * invW[2];
                            const float sum = l0 + l1 + l2;
                            Fragment f;
                            f.depth = 1.0f / sum;
                            f.object = bin.object;
                            f.facet = bin.facet;
                            const float w1 = (c1 == 1 ? l1 : l2) / sum,
                                        w2 = (c2 == 2 ? l2 : l1) / sum;
                            f.b1 = w1;
                            f.b2 = w2;
                            f.opaque = obj.opaque ? 1u : 0u;
                            ++st.fragments;
                            insertFragment(out, s, f, st);
                        }
                    }
                }
            }
    });
    stats = RasterStats{};
    for (const RasterStats& s : chunkStats) {
        stats.facets += s.facets;
        stats.facetsCulled += s.facetsCulled;
        stats.facetsDegenerate += s.facetsDegenerate;
        stats.facetsBackFacing += s.facetsBackFacing;
        stats.facetsInCulledClusters += s.facetsInCulledClusters;
    }
    for (const RasterStats& s : tileStats) {
        stats.facetsBinned += s.facetsBinned;
        stats.fragments += s.fragments;
        stats.droppedLayers += s.droppedLayers;
    }
}

}  // namespace mpshade
