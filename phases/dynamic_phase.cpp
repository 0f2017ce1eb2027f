#include "phases/dynamic_phase.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>

#include "phases/compositing.h"
#include "phases/work_deadline.h"

namespace mpshade {
namespace {

using Clock = std::chrono::steady_clock;

// Per cluster: whether any of it can be seen this frame. Off screen: its bounding sphere is
// wholly outside a side plane or in front of the near plane. Facing away: every normal of
// its cone points away from the eye for every point of its sphere (normal-cone culling).
void clusterVisibility(const FacetMesh& mesh, const ObjectState& state, const CameraState& camera,
                       bool backFaces, std::vector<uint8_t>& visible) {
    const float tx = camera.tanHalfFovY * camera.aspect, ty = camera.tanHalfFovY;
    const glm::vec3 planes[4] = {glm::normalize(camera.right - tx * camera.forward),
                                 glm::normalize(-camera.right - tx * camera.forward),
                                 glm::normalize(camera.up - ty * camera.forward),
                                 glm::normalize(-camera.up - ty * camera.forward)};
    visible.assign(mesh.clusters.size(), 1);
    for (size_t k = 0; k < mesh.clusters.size(); ++k) {
        const FacetCluster& c = mesh.clusters[k];
        const glm::vec3 d = glm::vec3(state.objectToWorld * glm::vec4(c.center, 1.0f)) - camera.eye;
        const float r = c.radius * state.scale;
        bool out = glm::dot(d, camera.forward) < camera.zNear - r;
        for (const glm::vec3& n : planes) out = out || glm::dot(d, n) > r;
        if (!out && backFaces && c.coneHalfAngle < 1.5f) {
            const glm::vec3 toCluster = c.center - state.eye;  // object space
            const float distance = glm::length(toCluster);
            if (distance > c.radius) {
                const float spread =
                    c.coneHalfAngle + std::asin(std::min(1.0f, c.radius / distance));
                out = spread < 1.5707963f &&
                      glm::dot(c.coneAxis, toCluster / distance) > std::sin(spread);
            }
        }
        visible[k] = out ? 0 : 1;
    }
}

// Back faces of a closed opaque surface are hidden only while the eye is outside the solid
// and the near plane cuts none of it: from inside, or through a near-plane cut, every
// surface seen faces away. Conservatively: culled while the object's bounding box, in its
// own space, stays farther from the eye than the near plane's corners.
bool backFacesHidden(const ObjectRepresentation& rep, const Surface& surface,
                     const ObjectState& state, const CameraState& camera) {
    if (!rep.opaque || !rep.closed) return false;
    const Bounds3 b = surfaceBounds(surface);
    const glm::vec3 nearest = glm::clamp(state.eye, b.lo, b.hi);
    const float distance = glm::length(state.eye - nearest) * state.scale;  // world units
    const float tx = camera.tanHalfFovY * camera.aspect, ty = camera.tanHalfFovY;
    return distance > camera.zNear * std::sqrt(1.0f + tx * tx + ty * ty) * 1.01f;
}

constexpr size_t kBatch = 1024;  // shading points per run of the dynamic shader
constexpr uint32_t kNoPoint = ~uint32_t{0};

}  // namespace

// A band's shading points and results, kept while it is unfinished (its points whose
// probes lacked tiles are shaded again after the fill, the rest are not) and reused from
// frame to frame; and per thread, the buffers of one batch.
struct DynamicPhase::Band {
    struct State {
        bool built = false;
        std::vector<uint32_t> object, facet;  // per shading point
        std::vector<float> x, y;              // per shading point, pixels
        std::vector<uint32_t> fragmentPoint;  // per visibility slot of the band
        // Per pixel of the band, shaded per pixel or per 2x2 pixels: its point, where that
        // one point is every sample's only fragment (its samples' fragmentPoint then unset);
        // otherwise kNoPoint. Empty when shaded per sample.
        std::vector<uint32_t> pixelPoint;
        std::vector<float> color, opacity;  // 3 per shading point
        // Points are grouped by object: object o's are [objectStart[o], objectStart[o + 1]).
        std::vector<uint32_t> objectStart;
        bool fresh = false;             // no point shaded yet: every point is pending
        std::vector<uint32_t> pending;  // otherwise, the points still to shade
    };
    struct Scratch {
        State work;  // the band being shaded, unless it has a state of its own
        std::vector<uint32_t> cursor, stillPending, permutation;
        std::vector<uint32_t> unsortedObject, unsortedFacet;
        std::vector<float> unsortedX, unsortedY;
        std::vector<uint32_t> batchFacet;
        std::vector<float> batchX, batchY, batchColor, batchOpacity;
        std::vector<uint8_t> batchMissed;
        std::vector<uint8_t> member;  // per fragment of a pixel block: its group
        SurfaceShadingScratch surface;
        SurfaceShadingCounters counters;
        std::vector<ObjectFrameCost> costs;  // per object
    };
    std::vector<State> states;
    tbb::enumerable_thread_specific<Scratch> scratch;
};

DynamicPhase::DynamicPhase(const Scene& scene)
    : scene_(scene), scratch_(std::make_unique<Band>()) {}
DynamicPhase::~DynamicPhase() = default;

void DynamicPhase::begin(const FrameState& frame,
                         std::span<const ObjectRepresentation* const> objects,
                         std::shared_ptr<const SampleLayout> layout,
                         const DynamicOptions& options) {
    auto start = Clock::now();
    frame_ = &frame;
    objects_.assign(objects.begin(), objects.end());
    layout_ = std::move(layout);
    options_ = options;
    stats_ = DynamicFrameStats{};
    const size_t n = objects_.size();
    costs_.assign(n, ObjectFrameCost{});
    warps_.resize(n);
    warped_.resize(n);
    clusterVisible_.resize(n);
    cullBack_.assign(n, 0);
    views_.assign(n, ObjectView{});
    const CameraState& camera = frame.camera;
    // The camera ray through screen position (x, y): d0 + x dx + y dy (world space).
    const float tx = camera.tanHalfFovY * camera.aspect, ty = camera.tanHalfFovY;
    const glm::vec3 d0 = camera.forward - tx * camera.right + ty * camera.up;
    const glm::vec3 ddx = (2.0f * tx / static_cast<float>(camera.width)) * camera.right;
    const glm::vec3 ddy = (-2.0f * ty / static_cast<float>(camera.height)) * camera.up;
    const float footprint =
        options.footprintScale * footprintPixels(options.shadingRate, layout_->spp());
    tbb::parallel_for(size_t{0}, n, [&](size_t i) {
        const ObjectRepresentation* rep = objects_[i];
        if (!rep) return;
        const ScopedSpan task(options.trace, "warp object", PhaseKind::Dynamic, SpanLevel::Task,
                              static_cast<int64_t>(i), frame.index);
        const ObjectState& state = frame.objects[i];
        const FacetMesh& mesh = rep->mesh;
        warps_[i] = std::make_unique<FixedPointWarp>(state.objectToWorld, camera, mesh.format);
        warps_[i]->warp(mesh.qx.data(), mesh.qy.data(), mesh.qz.data(), mesh.positionCount(),
                        warped_[i]);
        cullBack_[i] = backFacesHidden(*rep, *scene_.objects[i].surface, state, camera) ? 1 : 0;
        clusterVisibility(mesh, state, camera, cullBack_[i] != 0, clusterVisible_[i]);
        ObjectView& v = views_[i];
        v.rep = rep;
        v.uniforms = &frame.uniforms[i];
        v.eye = state.eye;
        const glm::mat3 toObject(state.worldToObject);
        v.d0 = toObject * d0;
        v.dx = toObject * ddx;
        v.dy = toObject * ddy;
        v.footprintScale = footprint;
        ObjectFrameCost& c = costs_[i];
        c.drawn = true;
        c.facets = mesh.facetCount();
        c.verticesWarped = mesh.positionCount();
    });
    for (size_t i = 0; i < n; ++i)
        if (objects_[i]) {
            stats_.facets += costs_[i].facets;
            stats_.verticesWarped += costs_[i].verticesWarped;
            stats_.facetBytes += objects_[i]->bytes();
        }
    stats_.warpSeconds = secondsSince(start);
    if (options.trace)
        options.trace->span("warp", PhaseKind::Dynamic, SpanLevel::Phase, start, Clock::now(), -1,
                            frame.index);

    start = Clock::now();
    std::vector<RasterObject> raster(n);
    for (size_t i = 0; i < n; ++i) {
        const ObjectRepresentation* rep = objects_[i];
        if (!rep) continue;
        raster[i] = {&rep->mesh,
                     &warped_[i],
                     warps_[i].get(),
                     rep->opaque,
                     cullBack_[i] != 0,
                     clusterVisible_[i].data(),
                     rep->kind == Representation::Facets ? &costs_[i].longestEdgePixels : nullptr};
    }
    RasterOptions rasterOptions = options.raster;
    rasterOptions.deadline = options.deadline;
    rasterizer_.rasterize(raster, *layout_, camera.zFar, rasterOptions, visibility_, stats_.raster);
    abandoned_ = stats_.raster.abandoned;
    stats_.rasterSeconds = secondsSince(start);
    if (options.trace)
        options.trace->span("rasterize", PhaseKind::Dynamic, SpanLevel::Phase, start, Clock::now(),
                            -1, frame.index);
    if (samples_.layout != layout_) {
        samples_.reset(layout_);
        uniform_.assign(static_cast<size_t>(layout_->width()) * layout_->height(), 0);
    }
    const int bands = (layout_->height() + options_.bandRows - 1) / options_.bandRows;
    bandDone_.assign(static_cast<size_t>(bands), 0);
    scratch_->states.resize(static_cast<size_t>(bands));
    for (Band::State& state : scratch_->states) state.built = false;
    for (Band::Scratch& s : scratch_->scratch) s.costs.assign(n, ObjectFrameCost{});
}

bool DynamicPhase::complete() const {
    return std::all_of(bandDone_.begin(), bandDone_.end(), [](uint8_t d) { return d != 0; });
}

std::vector<TileRequest> DynamicPhase::shade(bool acceptFallbacks) {
    const auto start = Clock::now();
    const ScopedSpan span(options_.trace, "shade", PhaseKind::Dynamic, SpanLevel::Phase, -1,
                          frame_->index);
    if (stats_.raster.abandoned) return {};  // no visibility to shade
    ++stats_.shadePasses;
    tbb::enumerable_thread_specific<std::vector<TileRequest>> lacking;
    WorkDeadline deadline(options_.deadline);
    tbb::parallel_for(size_t{0}, bandDone_.size(), [&](size_t b) {
        if (bandDone_[b] || deadline.passed()) return;
        const ScopedSpan task(options_.trace, "band", PhaseKind::Dynamic, SpanLevel::Task, -1,
                              frame_->index);
        shadeBand(b, acceptFallbacks, lacking.local());
    });
    abandoned_ = abandoned_ || deadline.missed();
    std::vector<TileRequest> all;
    for (const std::vector<TileRequest>& l : lacking) all.insert(all.end(), l.begin(), l.end());
    sortUniqueTiles(all);
    for (const TileRequest& r : all) ++costs_[r.object].tilesLacked;
    if (complete()) {
        // Sum the per-thread counters once every band is done.
        for (Band::Scratch& s : scratch_->scratch) {
            for (size_t i = 0; i < costs_.size() && i < s.costs.size(); ++i) {
                costs_[i].shadingPoints += s.costs[i].shadingPoints;
                costs_[i].instructions += s.costs[i].instructions;
                costs_[i].shadeSeconds += s.costs[i].shadeSeconds;
                costs_[i].probes += s.costs[i].probes;
                costs_[i].probeFallbacks += s.costs[i].probeFallbacks;
                s.costs[i] = ObjectFrameCost{};
            }
            stats_.instructions += s.counters.instructions;
            stats_.nonFinite += s.counters.nonFinite;
            s.counters = SurfaceShadingCounters{};
        }
        stats_.shadingPoints = stats_.probes = stats_.probeFallbacks = 0;
        for (const ObjectFrameCost& c : costs_) {
            stats_.shadingPoints += c.shadingPoints;
            stats_.probes += c.probes;
            stats_.probeFallbacks += c.probeFallbacks;
        }
    }
    stats_.shadeSeconds += secondsSince(start);
    return all;
}

void DynamicPhase::shadeBand(size_t band, bool acceptFallbacks, std::vector<TileRequest>& lacking) {
    // A band keeps a state of its own only while it waits for tiles: shaded in one pass,
    // it uses its thread's buffers and keeps nothing.
    Band::Scratch& s = scratch_->scratch.local();
    Band::State& st = scratch_->states[band].built ? scratch_->states[band] : s.work;
    if (s.costs.size() != objects_.size()) s.costs.assign(objects_.size(), ObjectFrameCost{});
    const SampleLayout& layout = *layout_;
    const VisibilityBuffer& vis = visibility_;
    const int width = layout.width(), spp = layout.spp(), layers = vis.layers;
    const int row0 = static_cast<int>(band) * options_.bandRows;
    const int row1 = std::min(layout.height(), row0 + options_.bandRows);
    const size_t firstSample = layout.index(0, row0, 0);
    const size_t endSample = layout.index(0, row1, 0);
    const size_t firstSlot = firstSample * static_cast<size_t>(layers);
    const size_t firstPixel = firstSample / static_cast<size_t>(spp);

    // 1. Shading points, once per frame.
    const size_t objects = objects_.size();
    if (!st.built) {
        st.fragmentPoint.resize((endSample - firstSample) * static_cast<size_t>(layers));
        st.objectStart.assign(objects + 1, 0);
        if (options_.shadingRate == ShadingRate::Sample) {
            // A point per fragment, placed by object as it is made (a counting sort).
            st.pixelPoint.clear();
            for (size_t smp = firstSample; smp < endSample; ++smp)
                for (int l = 0; l < vis.count[smp]; ++l)
                    ++st.objectStart[vis.object[smp * layers + l] + 1];
            for (size_t o = 0; o < objects; ++o) st.objectStart[o + 1] += st.objectStart[o];
            const size_t points = st.objectStart[objects];
            st.object.resize(points), st.facet.resize(points);
            st.x.resize(points), st.y.resize(points);
            s.cursor.assign(st.objectStart.begin(), st.objectStart.end() - 1);
            for (size_t smp = firstSample; smp < endSample; ++smp)
                for (int l = 0; l < vis.count[smp]; ++l) {
                    const size_t slot = smp * layers + l;
                    const uint32_t o = vis.object[slot];
                    const uint32_t at = s.cursor[o]++;
                    st.object[at] = o;
                    st.facet[at] = vis.facet[slot];
                    st.x[at] = layout.x(smp);
                    st.y[at] = layout.y(smp);
                    st.fragmentPoint[slot - firstSlot] = at;
                }
        } else {
            s.unsortedObject.clear(), s.unsortedFacet.clear();
            s.unsortedX.clear(), s.unsortedY.clear();
            auto addPoint = [&](uint32_t o, uint32_t f, float x, float y) {
                s.unsortedObject.push_back(o);
                s.unsortedFacet.push_back(f);
                s.unsortedX.push_back(x);
                s.unsortedY.push_back(y);
                return static_cast<uint32_t>(s.unsortedObject.size() - 1);
            };
            struct Group {
                uint32_t object;
                int layer;
                float sx, sy;
                int count;
            };
            Group groups[64];
            st.pixelPoint.assign(static_cast<size_t>(row1 - row0) * static_cast<size_t>(width),
                                 kNoPoint);
            auto pixelAt = [&](int px, int py) {
                return static_cast<size_t>(py - row0) * static_cast<size_t>(width) +
                       static_cast<size_t>(px);
            };
            // Per pixel, or per block of 2x2 pixels: the block's fragments grouped by
            // surface. member: per (pixel of the block, sample, layer), its group.
            const int block = options_.shadingRate == ShadingRate::Quad ? 2 : 1;
            const size_t pixelSlots = static_cast<size_t>(spp) * layers;
            s.member.resize(static_cast<size_t>(block * block) * pixelSlots);
            for (int by = row0; by < row1; by += block)
                for (int bx = 0; bx < width; bx += block) {
                    if (block == 1 && options_.wholePixelShortcut) {
                        // The common case: one surface covers every sample of the pixel, in
                        // front. Its point is the pixel's precomputed centroid, on the facet
                        // of its nearest sample: what the general path below finds.
                        const size_t first = layout.index(bx, by, 0);
                        bool whole = vis.count[first] == 1;
                        const uint32_t o = whole ? vis.object[first * layers] : 0;
                        for (int k = 1; k < spp && whole; ++k)
                            whole =
                                vis.count[first + k] == 1 && vis.object[(first + k) * layers] == o;
                        if (whole) {
                            const size_t pixel = first / static_cast<size_t>(spp);
                            const size_t nearest =
                                first + static_cast<size_t>(layout.nearestToCentroid(pixel));
                            st.pixelPoint[pixelAt(bx, by)] =
                                addPoint(o, vis.facet[nearest * layers], layout.centroidX(pixel),
                                         layout.centroidY(pixel));
                            continue;
                        }
                    }
                    const int y1 = std::min(row1, by + block), x1 = std::min(width, bx + block);
                    if (block == 2 && options_.wholePixelShortcut && x1 - bx == 2 && y1 - by == 2 &&
                        by % 2 == 0) {
                        // The same for a whole 2x2 block: its four pixels' samples all see
                        // one surface, in front.
                        const size_t firsts[4] = {
                            layout.index(bx, by, 0), layout.index(bx + 1, by, 0),
                            layout.index(bx, by + 1, 0), layout.index(bx + 1, by + 1, 0)};
                        bool whole = vis.count[firsts[0]] == 1;
                        const uint32_t o = whole ? vis.object[firsts[0] * layers] : 0;
                        for (int q = 0; q < 4 && whole; ++q)
                            for (int k = 0; k < spp && whole; ++k)
                                whole = vis.count[firsts[q] + k] == 1 &&
                                        vis.object[(firsts[q] + k) * layers] == o;
                        if (whole) {
                            const size_t quad = static_cast<size_t>(by / 2) * (width / 2) + bx / 2;
                            const int m = layout.nearestToQuadCentroid(quad);
                            const size_t nearest = firsts[m / spp] + static_cast<size_t>(m % spp);
                            const uint32_t point =
                                addPoint(o, vis.facet[nearest * layers], layout.quadCentroidX(quad),
                                         layout.quadCentroidY(quad));
                            for (int dy = 0; dy < 2; ++dy)
                                for (int dx = 0; dx < 2; ++dx)
                                    st.pixelPoint[pixelAt(bx + dx, by + dy)] = point;
                            continue;
                        }
                    }
                    // Calls f(sample, layer, member index) for every fragment of the block.
                    auto forEachFragment = [&](auto&& f) {
                        for (int py = by; py < y1; ++py)
                            for (int px = bx; px < x1; ++px) {
                                const size_t first = layout.index(px, py, 0);
                                const size_t m0 =
                                    static_cast<size_t>((py - by) * block + (px - bx)) * pixelSlots;
                                for (int k = 0; k < spp; ++k)
                                    for (int l = 0; l < vis.count[first + k]; ++l)
                                        f(first + k, l, m0 + static_cast<size_t>(k * layers + l));
                            }
                    };
                    int groupCount = 0;
                    forEachFragment([&](size_t smp, int l, size_t m) {
                        const uint32_t o = vis.object[smp * layers + l];
                        int g = 0;
                        while (g < groupCount && !(groups[g].object == o && groups[g].layer == l))
                            ++g;
                        if (g == groupCount) {
                            if (groupCount == 64)
                                g = 0;  // more surfaces than that: merge
                            else
                                groups[groupCount++] = {o, l, 0.0f, 0.0f, 0};
                        }
                        groups[g].sx += layout.x(smp);
                        groups[g].sy += layout.y(smp);
                        ++groups[g].count;
                        s.member[m] = static_cast<uint8_t>(g);
                    });
                    // Each group's point: its centroid, on the facet of the member sample
                    // nearest to it (the first such, in sample order).
                    float cx[64], cy[64], best[64];
                    uint32_t facet[64], pointOf[64];
                    for (int g = 0; g < groupCount; ++g) {
                        cx[g] = groups[g].sx / groups[g].count;
                        cy[g] = groups[g].sy / groups[g].count;
                        best[g] = 1e30f;
                        facet[g] = 0;
                    }
                    forEachFragment([&](size_t smp, int l, size_t m) {
                        const int g = s.member[m];
                        const float dx = layout.x(smp) - cx[g], dy = layout.y(smp) - cy[g];
                        if (dx * dx + dy * dy < best[g]) {
                            best[g] = dx * dx + dy * dy;
                            facet[g] = vis.facet[smp * layers + l];
                        }
                    });
                    for (int g = 0; g < groupCount; ++g)
                        pointOf[g] = addPoint(groups[g].object, facet[g], cx[g], cy[g]);
                    forEachFragment([&](size_t smp, int l, size_t m) {
                        st.fragmentPoint[smp * layers + l - firstSlot] = pointOf[s.member[m]];
                    });
                }
            // Grouped by object (a counting sort), the fragments following their points.
            const size_t points = s.unsortedObject.size();
            for (uint32_t o : s.unsortedObject) ++st.objectStart[o + 1];
            for (size_t o = 0; o < objects; ++o) st.objectStart[o + 1] += st.objectStart[o];
            st.object.resize(points), st.facet.resize(points);
            st.x.resize(points), st.y.resize(points);
            s.cursor.assign(st.objectStart.begin(), st.objectStart.end() - 1);
            s.permutation.resize(points);
            for (size_t p = 0; p < points; ++p) {
                const uint32_t at = s.cursor[s.unsortedObject[p]]++;
                s.permutation[p] = at;
                st.object[at] = s.unsortedObject[p];
                st.facet[at] = s.unsortedFacet[p];
                st.x[at] = s.unsortedX[p];
                st.y[at] = s.unsortedY[p];
            }
            for (size_t pixel = firstPixel; pixel < endSample / spp; ++pixel) {
                uint32_t& whole = st.pixelPoint[pixel - firstPixel];
                if (whole != kNoPoint) {
                    whole = s.permutation[whole];
                    continue;
                }
                for (size_t smp = pixel * spp; smp < (pixel + 1) * spp; ++smp)
                    for (int l = 0; l < vis.count[smp]; ++l) {
                        uint32_t& point = st.fragmentPoint[smp * layers + l - firstSlot];
                        point = s.permutation[point];
                    }
            }
        }
        const size_t points = st.object.size();
        st.color.resize(3 * points);
        st.opacity.resize(3 * points);
        st.pending.clear();
        st.fresh = true;
        st.built = true;
    }

    // 2. Each object's points in batches; those whose probes lacked tiles stay pending.
    //    The first time, every point: the batches are runs of the band's own arrays.
    s.batchMissed.resize(kBatch);
    s.stillPending.clear();
    auto addObjectCosts = [&](size_t o, const SurfaceShadingCounters& counters,
                              Clock::time_point began) {
        for (const TileKey& key : s.surface.missing)
            lacking.push_back({static_cast<uint32_t>(o), key});
        ObjectFrameCost& cost = s.costs[o];
        cost.shadeSeconds += secondsSince(began);
        cost.instructions += counters.instructions;
        cost.probes += counters.probes;
        cost.probeFallbacks += counters.fallbacks;
        s.counters.instructions += counters.instructions;
        s.counters.nonFinite += counters.nonFinite;
    };
    // After a fill, the points still pending (in order, so grouped by object), gathered
    // into batches and their results scattered back.
    auto shadePending = [&] {
        s.batchFacet.resize(kBatch);
        s.batchX.resize(kBatch), s.batchY.resize(kBatch);
        s.batchColor.resize(3 * kBatch), s.batchOpacity.resize(3 * kBatch);
        size_t first = 0;
        while (first < st.pending.size()) {
            const uint32_t o = st.object[st.pending[first]];
            size_t last = first;
            while (last < st.pending.size() && st.object[st.pending[last]] == o) ++last;
            const auto began = Clock::now();
            SurfaceShadingCounters counters;
            s.surface.missing.clear();
            for (size_t b = first; b < last; b += kBatch) {
                const size_t m = std::min(kBatch, last - b);
                for (size_t i = 0; i < m; ++i) {
                    const uint32_t p = st.pending[b + i];
                    s.batchFacet[i] = st.facet[p];
                    s.batchX[i] = st.x[p];
                    s.batchY[i] = st.y[p];
                }
                const SurfacePoints batch{s.batchFacet.data(), s.batchX.data(), s.batchY.data(), m};
                const size_t missed = shadeSurfacePoints(
                    views_[o], options_.probe, !acceptFallbacks, batch, s.batchColor.data(),
                    s.batchOpacity.data(), s.batchMissed.data(), s.surface, counters);
                for (size_t i = 0; i < m; ++i) {
                    const uint32_t p = st.pending[b + i];
                    if (missed > 0 && s.batchMissed[i]) {
                        s.stillPending.push_back(p);
                        continue;
                    }
                    for (int k = 0; k < 3; ++k) {
                        st.color[3 * p + k] = s.batchColor[3 * i + k];
                        st.opacity[3 * p + k] = s.batchOpacity[3 * i + k];
                    }
                }
            }
            addObjectCosts(o, counters, began);
            first = last;
        }
    };
    if (st.fresh) {
        for (size_t o = 0; o < objects; ++o) {
            const size_t begin = st.objectStart[o], end = st.objectStart[o + 1];
            if (begin == end) continue;
            const auto began = Clock::now();
            SurfaceShadingCounters counters;
            s.surface.missing.clear();
            for (size_t b = begin; b < end; b += kBatch) {
                const size_t m = std::min(kBatch, end - b);
                const SurfacePoints batch{&st.facet[b], &st.x[b], &st.y[b], m};
                const size_t missed = shadeSurfacePoints(
                    views_[o], options_.probe, !acceptFallbacks, batch, &st.color[3 * b],
                    &st.opacity[3 * b], s.batchMissed.data(), s.surface, counters);
                if (missed > 0)
                    for (size_t i = 0; i < m; ++i)
                        if (s.batchMissed[i])
                            s.stillPending.push_back(static_cast<uint32_t>(b + i));
            }
            addObjectCosts(o, counters, began);
        }
        st.fresh = false;
    } else {
        shadePending();
    }
    st.pending.swap(s.stillPending);
    if (!st.pending.empty()) {
        // Shaded again once the lacking tiles are filled: the band keeps these buffers.
        if (&st == &s.work) std::swap(s.work, scratch_->states[band]);
        return;
    }

    // 3. Composite every sample front to back over the background; note the pixels whose
    //    samples all came out alike (the resolve reads those once). A pixel one point
    //    covers whole has all its samples alike: only its first is composited and written,
    //    the one the resolve reads (at per-pixel shading, three quarters of the samples'
    //    passes over memory).
    const glm::vec3 background = scene_.settings.background;
    for (size_t pixel = firstPixel; pixel < endSample / spp; ++pixel) {
        const size_t first = pixel * static_cast<size_t>(spp);
        if (!st.pixelPoint.empty()) {
            if (const uint32_t p = st.pixelPoint[pixel - firstPixel]; p != kNoPoint) {
                SampleComposite c;
                c.over(&st.color[3 * p], &st.opacity[3 * p]);
                c.finish(background, &samples_.rgba[4 * first]);
                uniform_[pixel] = 1;
                continue;
            }
        }
        for (size_t smp = first; smp < first + spp; ++smp) {
            SampleComposite c;
            for (int l = 0; l < vis.count[smp]; ++l) {
                const uint32_t p = st.fragmentPoint[smp * layers + l - firstSlot];
                c.over(&st.color[3 * p], &st.opacity[3 * p]);
            }
            c.finish(background, &samples_.rgba[4 * smp]);
        }
        const float* rgba = &samples_.rgba[4 * first];
        bool same = true;
        for (int k = 1; k < spp && same; ++k)
            same = std::memcmp(rgba, rgba + 4 * k, 4 * sizeof(float)) == 0;
        uniform_[pixel] = same ? 1 : 0;
    }
    for (size_t o = 0; o < objects; ++o)
        s.costs[o].shadingPoints += st.objectStart[o + 1] - st.objectStart[o];
    st.built = false;
    if (&st != &s.work) std::swap(s.work, st);  // its buffers go back to the thread
    bandDone_[band] = 1;
}

void DynamicPhase::resolve(Image& out) {
    const auto start = Clock::now();
    const ScopedSpan span(options_.trace, "resolve", PhaseKind::Resolve, SpanLevel::Phase, -1,
                          frame_->index);
    layout_->resolve(samples_.rgba.data(), uniform_.data(), out,
                     options_.shadingRate == ShadingRate::Quad);
    stats_.resolveSeconds = secondsSince(start);
}

}  // namespace mpshade
