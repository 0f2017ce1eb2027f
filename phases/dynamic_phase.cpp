#include "phases/dynamic_phase.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <glm/geometric.hpp>

#include "geometry/ray_scene.h"
#include "phases/band_points.h"
#include "phases/compositing.h"
#include "phases/view_reuse.h"
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

}  // namespace

// Per band, its shading points while it waits for tiles (band_points.h); per thread, the
// buffers of the band being shaded and of one batch, and what shading cost.
struct DynamicPhase::Band {
    struct Scratch {
        BandPoints work;  // the band being shaded, unless it has points of its own
        BandPointScratch points;
        std::vector<uint32_t> stillPending;
        std::vector<uint32_t> batchFacet;
        std::vector<float> batchX, batchY, batchColor, batchOpacity;
        std::vector<uint8_t> batchMissed;
        SurfaceShadingScratch surface;
        SurfaceShadingCounters counters;
        std::vector<const float*> keptChannels;  // replay: the kept n-tuple channels of a batch
        std::vector<ObjectFrameCost> costs;      // per object
        DynamicFrameStats::ShadeParts parts;     // this thread's, since the frame's last sum

        // Every point of a fresh band, each object's as runs of the band's own arrays; the
        // points whose probes found tiles missing go to stillPending.
        // With `keep`, each batch's inputs are appended to it, and false is returned if any
        // batch missed a tile or read a coarser level (the inputs are then not the band's).
        bool shadeFresh(std::span<const ObjectView> views, const ProbeOptions& probe,
                        bool stopAtMissing, BandPoints& pts, std::vector<TileRequest>& missing,
                        const InputLayout& layout, BandInputs* keep);
        // Every point of a band whose view held still, on the inputs it kept: the same
        // batches shadeFresh made, the dynamic shader alone.
        void replay(std::span<const ObjectView> views, BandPoints& pts, const InputLayout& layout,
                    const BandInputs& kept);
        // After a fill, the points still pending (in order, so grouped by object), gathered
        // into batches and their results scattered back.
        void shadePending(std::span<const ObjectView> views, const ProbeOptions& probe,
                          bool stopAtMissing, BandPoints& pts, std::vector<TileRequest>& missing);
        // What shading object o's points cost, and the tiles its probes found missing.
        void addObjectCosts(size_t o, const SurfaceShadingCounters& c, Clock::time_point began,
                            std::vector<TileRequest>& missing);
    };
    std::vector<BandPoints> states;
    std::vector<BandInputs> inputs;  // per band, while the view holds still (view_reuse.h)
    tbb::enumerable_thread_specific<Scratch> scratch;
    // refine()'s, apart, so that its counts stay out of the frame's.
    tbb::enumerable_thread_specific<Scratch> refine;
};

bool DynamicPhase::Band::Scratch::shadeFresh(std::span<const ObjectView> views,
                                             const ProbeOptions& probe, bool stopAtMissing,
                                             BandPoints& pts, std::vector<TileRequest>& missing,
                                             const InputLayout& layout, BandInputs* keep) {
    bool whole = true;
    for (size_t o = 0; o + 1 < pts.objectStart.size(); ++o) {
        const size_t begin = pts.objectStart[o], end = pts.objectStart[o + 1];
        if (begin == end) continue;
        const auto began = Clock::now();
        SurfaceShadingCounters c;
        surface.missing.clear();
        for (size_t b = begin; b < end; b += kBatch) {
            const size_t m = std::min(kBatch, end - b);
            const SurfacePoints batch{&pts.facet[b], &pts.x[b], &pts.y[b], m};
            const uint64_t fallbacks = c.fallbacks;
            const size_t missed =
                shadeSurfacePoints(views[o], probe, stopAtMissing, batch, &pts.color[3 * b],
                                   &pts.opacity[3 * b], batchMissed.data(), surface, c);
            if (missed > 0)
                for (size_t i = 0; i < m; ++i)
                    if (batchMissed[i]) stillPending.push_back(static_cast<uint32_t>(b + i));
            whole = whole && missed == 0 && c.fallbacks == fallbacks;
            if (keep && whole) keep->append(surface.batch, layout.rows[o], layout.channels[o], m);
        }
        addObjectCosts(o, c, began, missing);
    }
    return whole;
}

void DynamicPhase::Band::Scratch::replay(std::span<const ObjectView> views, BandPoints& pts,
                                         const InputLayout& layout, const BandInputs& kept) {
    size_t cursor = 0;
    for (size_t o = 0; o + 1 < pts.objectStart.size(); ++o) {
        const size_t begin = pts.objectStart[o], end = pts.objectStart[o + 1];
        if (begin == end) continue;
        const auto began = Clock::now();
        SurfaceShadingCounters c;
        surface.missing.clear();
        for (size_t b = begin; b < end; b += kBatch) {
            const size_t m = std::min(kBatch, end - b);
            surface.batch.resize(m, layout.channels[o]);  // outputs; unkept rows unread
            ShadingInputs in = surface.batch.in;
            kept.restore(in, keptChannels, layout.rows[o], layout.channels[o], m, cursor);
            runDynamicShader(views[o], in, m, &pts.color[3 * b], &pts.opacity[3 * b], surface, c);
        }
        std::vector<TileRequest> none;
        addObjectCosts(o, c, began, none);
        costs[o].pointsReplayed += end - begin;
    }
}

void DynamicPhase::Band::Scratch::shadePending(std::span<const ObjectView> views,
                                               const ProbeOptions& probe, bool stopAtMissing,
                                               BandPoints& pts, std::vector<TileRequest>& missing) {
    batchFacet.resize(kBatch);
    batchX.resize(kBatch), batchY.resize(kBatch);
    batchColor.resize(3 * kBatch), batchOpacity.resize(3 * kBatch);
    size_t first = 0;
    while (first < pts.pending.size()) {
        const uint32_t o = pts.object[pts.pending[first]];
        size_t last = first;
        while (last < pts.pending.size() && pts.object[pts.pending[last]] == o) ++last;
        const auto began = Clock::now();
        SurfaceShadingCounters c;
        surface.missing.clear();
        for (size_t b = first; b < last; b += kBatch) {
            const size_t m = std::min(kBatch, last - b);
            for (size_t i = 0; i < m; ++i) {
                const uint32_t p = pts.pending[b + i];
                batchFacet[i] = pts.facet[p];
                batchX[i] = pts.x[p];
                batchY[i] = pts.y[p];
            }
            const SurfacePoints batch{batchFacet.data(), batchX.data(), batchY.data(), m};
            const size_t missed =
                shadeSurfacePoints(views[o], probe, stopAtMissing, batch, batchColor.data(),
                                   batchOpacity.data(), batchMissed.data(), surface, c);
            for (size_t i = 0; i < m; ++i) {
                const uint32_t p = pts.pending[b + i];
                if (missed > 0 && batchMissed[i]) {
                    stillPending.push_back(p);
                    continue;
                }
                for (int k = 0; k < 3; ++k) {
                    pts.color[3 * p + k] = batchColor[3 * i + k];
                    pts.opacity[3 * p + k] = batchOpacity[3 * i + k];
                }
            }
        }
        addObjectCosts(o, c, began, missing);
        first = last;
    }
}

void DynamicPhase::Band::Scratch::addObjectCosts(size_t o, const SurfaceShadingCounters& c,
                                                 Clock::time_point began,
                                                 std::vector<TileRequest>& missing) {
    for (const TileKey& key : surface.missing) missing.push_back({static_cast<uint32_t>(o), key});
    ObjectFrameCost& cost = costs[o];
    cost.shadeSeconds += secondsSince(began);
    cost.instructions += c.instructions;
    cost.probes += c.probes;
    cost.probeFallbacks += c.fallbacks;
    counters.instructions += c.instructions;
    counters.nonFinite += c.nonFinite;
    parts.interpolate += c.interpolateSeconds;
    parts.probe += c.probeSeconds;
    parts.kernel += c.kernelSeconds;
}

namespace {

// Composites every sample of the band front to back over the background and notes the
// pixels whose samples all came out alike (the resolve reads those once). A pixel one point
// covers whole has all its samples alike: only its first is composited and written, the one
// the resolve reads (at per-pixel shading, three quarters of the samples' passes over
// memory). The band's arrays are looked up once, and samples of several layers composited
// out of line: a pixel's loop had reloaded them through the band's structures and kept its
// sample counter on the stack.
class BandCompositor {
  public:
    BandCompositor(const BandPoints& pts, const BandRange& r, const VisibilityBuffer& vis, int spp,
                   const glm::vec3& background, float* rgbaOut, uint8_t* uniform)
        : count_(vis.count.data()),
          fragment_(pts.fragmentPoint.data()),
          pixelPoint_(pts.pixelPoint.empty() ? nullptr : pts.pixelPoint.data()),
          color_(pts.color.data()),
          opacity_(pts.opacity.data()),
          rgbaOut_(rgbaOut),
          uniform_(uniform),
          layers_(static_cast<size_t>(vis.layers)),
          spp_(static_cast<size_t>(spp)),
          firstSlot_(r.firstSlot),
          firstPixel_(r.firstPixel),
          background_(background),
          background4_{background.x, background.y, background.z, 0.0f} {}

    void pixel(size_t pixel) const {
        const size_t first = pixel * spp_;
        if (pixelPoint_) {
            if (const uint32_t p = pixelPoint_[pixel - firstPixel_]; p != kNoPoint) {
                SampleComposite c;
                c.over(&color_[3 * p], &opacity_[3 * p]);
                c.finish(background_, &rgbaOut_[4 * first]);
                uniform_[pixel] = 1;
                return;
            }
        }
        // Whether the pixel's samples came out alike is decided on the values in registers:
        // reading the samples back from rgbaOut waited on their stores (the whole band's
        // composite took a fifth of the shading time of a one-sphere scene).
        const Float4 zero = {}, one = splatFloat4(1.0f);
        Float4 firstRgba = zero;
        bool same = true;
        for (size_t smp = first; smp < first + spp_; ++smp) {
            Float4 rgba;
            const uint8_t surfaces = count_[smp];
            if (surfaces == 1) {
                // One surface (most samples): SampleComposite's arithmetic written out for one
                // layer in one vector, the same bits without its loops over layers and
                // channels. A point's three floats are read as four (BandPoints pads its rows
                // by one).
                const uint32_t p = fragment_[smp * layers_ - firstSlot_];
                const Float4 ci = loadFloat4(&color_[3 * p]);
                const Float4 oi = loadFloat4(&opacity_[3 * p]);
                const Float4 t = one - oi;
                rgba = (zero + oi * ci) + t * background4_;
                rgba[3] = 1.0f - (t[0] + t[1] + t[2]) / 3.0f;
            } else if (surfaces == 0) {
                // The background alone: SampleComposite's finish with nothing over it (C 0,
                // T 1; 0 + 1 bg rather than bg, so a -0 comes out +0 as there), coverage 0.
                rgba = zero + one * background4_;
                rgba[3] = 0.0f;
            } else {
                rgba = layered(smp, surfaces);
            }
            storeFloat4(&rgbaOut_[4 * smp], rgba);
            // Bit for bit, as the resolve compares alike blocks.
            const Int4 differ = reinterpret_cast<Int4>(rgba) ^ reinterpret_cast<Int4>(firstRgba);
            if (smp == first)
                firstRgba = rgba;
            else
                same = same && (differ[0] | differ[1] | differ[2] | differ[3]) == 0;
        }
        uniform_[pixel] = same ? 1 : 0;
    }

  private:
    [[gnu::noinline]] Float4 layered(size_t smp, int surfaces) const {
        SampleComposite c;
        for (int l = 0; l < surfaces; ++l) {
            const uint32_t p = fragment_[smp * layers_ + static_cast<size_t>(l) - firstSlot_];
            c.over(&color_[3 * p], &opacity_[3 * p]);
        }
        float out[4];
        c.finish(background_, out);
        return loadFloat4(out);
    }

    const uint8_t* count_;
    const uint32_t* fragment_;
    const uint32_t* pixelPoint_;
    const float* color_;
    const float* opacity_;
    float* rgbaOut_;
    uint8_t* uniform_;
    size_t layers_, spp_, firstSlot_, firstPixel_;
    glm::vec3 background_;
    Float4 background4_;
};

// A band's (or a refined tile's) pixels, row by row.
void compositeBand(const BandPoints& pts, const BandRange& r, const VisibilityBuffer& vis,
                   int width, int spp, const glm::vec3& background, float* rgbaOut,
                   uint8_t* uniform) {
    const BandCompositor compositor(pts, r, vis, spp, background, rgbaOut, uniform);
    for (int py = r.row0; py < r.row1; ++py) {
        const size_t row = static_cast<size_t>(py) * static_cast<size_t>(width);
        for (size_t pixel = row + r.col0; pixel < row + r.col1; ++pixel) compositor.pixel(pixel);
    }
}

}  // namespace

DynamicPhase::DynamicPhase(const Scene& scene)
    : scene_(scene), scratch_(std::make_unique<Band>()) {}
DynamicPhase::~DynamicPhase() = default;

void DynamicPhase::begin(const FrameState& frame,
                         std::span<const ObjectRepresentation* const> objects,
                         std::shared_ptr<const SampleLayout> layout,
                         const DynamicOptions& options) {
    frame_ = &frame;
    objects_.assign(objects.begin(), objects.end());
    layout_ = std::move(layout);
    options_ = options;
    stats_ = DynamicFrameStats{};
    costs_.assign(objects_.size(), ObjectFrameCost{});
    compareWithLastView();
    warpObjects();
    if (reusing_) {
        // The visibility buffer is the last frame's, which saw the same.
        abandoned_ = false;
    } else {
        rasterizeObjects();
    }
    prepareBands();
}

// Whether this frame sees what the last one did (view_reuse.h): then it reuses the
// visibility and the bands' kept inputs. Bands keep inputs at a frame whose view held
// still since the last, or at the first: a camera in motion never pays for keeping them.
void DynamicPhase::compareWithLastView() {
    const size_t n = objects_.size();
    ViewKey key;
    key.camera = frame_->camera;
    key.layout = layout_.get();
    key.shadingRate = static_cast<int>(options_.shadingRate);
    key.footprintScale = options_.footprintScale;
    key.objectFootprint = options_.objectFootprint;
    key.probe = options_.probe;
    key.bandRows = options_.bandRows;
    key.wholePixelShortcut = options_.wholePixelShortcut;
    key.serials.assign(n, 0);
    key.placements.assign(n, glm::mat4(0.0f));
    for (size_t i = 0; i < n; ++i)
        if (objects_[i]) {
            key.serials[i] = objects_[i]->serial;
            key.placements[i] = frame_->objects[i].objectToWorld;
        }
    const bool still = haveLastView_ && key == lastView_;
    reusing_ = options_.reuseBytes > 0 && still && lastViewWhole_;
    // The same frame again (play's first frame after its pre-roll rendered it at each step)
    // says nothing of whether the animation holds still: it keeps as a first frame does.
    const bool sameFrame = haveLastView_ && frame_->index == lastViewFrame_;
    keeping_ =
        options_.reuseBytes > 0 && (!haveLastView_ || sameFrame ? options_.keepFirstView : still);
    lastView_ = std::move(key);
    lastViewFrame_ = frame_->index;
    haveLastView_ = true;
    stats_.viewReused = reusing_;
    inputLayout_.rows.assign(n, {});
    inputLayout_.channels.assign(n, 0);
    for (size_t i = 0; i < n; ++i)
        if (objects_[i]) {
            inputLayout_.rows[i] = shadingInputRows(*objects_[i]);
            inputLayout_.channels[i] = shadingChannels(*objects_[i]);
        }
}

// Each drawn object's view of the frame; and, unless the last frame's visibility serves,
// its vertices warped to the screen and its clusters culled.
void DynamicPhase::warpObjects() {
    const auto start = Clock::now();
    const FrameState& frame = *frame_;
    const size_t n = objects_.size();
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
        options_.footprintScale * footprintPixels(options_.shadingRate, layout_->spp());
    tbb::parallel_for(size_t{0}, n, [&](size_t i) {
        const ObjectRepresentation* rep = objects_[i];
        if (!rep) return;
        const ScopedSpan task(options_.trace, "warp object", PhaseKind::Dynamic, SpanLevel::Task,
                              static_cast<int64_t>(i), frame.index);
        const ObjectState& state = frame.objects[i];
        const FacetMesh& mesh = rep->mesh;
        ObjectFrameCost& c = costs_[i];
        c.drawn = true;
        c.facets = mesh.facetCount();
        if (!reusing_) {
            warps_[i] = std::make_unique<FixedPointWarp>(state.objectToWorld, camera, mesh.format);
            warps_[i]->warp(mesh.qx.data(), mesh.qy.data(), mesh.qz.data(), mesh.positionCount(),
                            warped_[i]);
            cullBack_[i] = backFacesHidden(*rep, *scene_.objects[i].surface, state, camera) ? 1 : 0;
            clusterVisibility(mesh, state, camera, cullBack_[i] != 0, clusterVisible_[i]);
            c.verticesWarped = mesh.positionCount();
        }
        ObjectView& v = views_[i];
        v.rep = rep;
        v.uniforms = &frame.uniforms[i];
        v.eye = state.eye;
        const glm::mat3 toObject(state.worldToObject);
        v.d0 = toObject * d0;
        v.dx = toObject * ddx;
        v.dy = toObject * ddy;
        v.footprintScale = footprint * objectFootprintAt(options_.objectFootprint, i);
    });
    for (size_t i = 0; i < n; ++i)
        if (objects_[i]) {
            stats_.facets += costs_[i].facets;
            stats_.verticesWarped += costs_[i].verticesWarped;
            stats_.facetBytes += objects_[i]->bytes();
        }
    stats_.warpSeconds = secondsSince(start);
    if (options_.trace)
        options_.trace->span("warp", PhaseKind::Dynamic, SpanLevel::Phase, start, Clock::now(), -1,
                             frame.index);
}

void DynamicPhase::rasterizeObjects() {
    const auto start = Clock::now();
    const size_t n = objects_.size();
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
    RasterOptions rasterOptions = options_.raster;
    rasterOptions.deadline = options_.deadline;
    rasterizer_.rasterize(raster, *layout_, frame_->camera.zFar, rasterOptions, visibility_,
                          stats_.raster);
    abandoned_ = stats_.raster.abandoned;
    lastViewWhole_ = !abandoned_;
    stats_.rasterSeconds = secondsSince(start);
    if (options_.trace)
        options_.trace->span("rasterize", PhaseKind::Dynamic, SpanLevel::Phase, start, Clock::now(),
                             -1, frame_->index);
}

// The bands to shade: every one undone; a band keeps its points and inputs only while the
// view holds still.
void DynamicPhase::prepareBands() {
    if (samples_.layout != layout_) {
        samples_.reset(layout_);
        uniform_.assign(static_cast<size_t>(layout_->width()) * layout_->height(), 0);
    }
    const size_t bands =
        static_cast<size_t>((layout_->height() + options_.bandRows - 1) / options_.bandRows);
    bandDone_.assign(bands, 0);
    scratch_->states.resize(bands);
    scratch_->inputs.resize(bands);
    keptBytes_ = 0;
    for (size_t b = 0; b < bands; ++b) {
        BandInputs& kept = scratch_->inputs[b];
        if (reusing_ && kept.valid() && scratch_->states[b].built) {
            keptBytes_ += kept.bytes();
            continue;
        }
        kept.invalidate();
        if (options_.reuseBytes == 0) kept.release();
        scratch_->states[b].built = false;
    }
    for (Band::Scratch& s : scratch_->scratch) s.costs.assign(objects_.size(), ObjectFrameCost{});
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
    tbb::enumerable_thread_specific<std::vector<TileRequest>> missing;
    WorkDeadline deadline(options_.deadline);
    tbb::parallel_for(size_t{0}, bandDone_.size(), [&](size_t b) {
        if (bandDone_[b] || deadline.passed()) return;
        // Denormals flushed in every task that shades, as in those that fill tiles and
        // trace the reference. TBB runs a task in the float mode of the thread that started
        // it, and whether that one's was flushed depended on whether a static fill's task
        // had run on it before: a denormal result, and a frame's bits, with it.
        enableFlushToZero();
        const ScopedSpan task(options_.trace, "band", PhaseKind::Dynamic, SpanLevel::Task, -1,
                              frame_->index);
        shadeBand(b, acceptFallbacks, missing.local());
    });
    abandoned_ = abandoned_ || deadline.missed();
    std::vector<TileRequest> all;
    for (const std::vector<TileRequest>& l : missing) all.insert(all.end(), l.begin(), l.end());
    sortUniqueTiles(all);
    for (const TileRequest& r : all) ++costs_[r.object].tilesMissing;
    if (complete()) {
        // Sum the per-thread counters once every band is done.
        for (Band::Scratch& s : scratch_->scratch) {
            for (size_t i = 0; i < costs_.size() && i < s.costs.size(); ++i) {
                costs_[i].shadingPoints += s.costs[i].shadingPoints;
                costs_[i].instructions += s.costs[i].instructions;
                costs_[i].shadeSeconds += s.costs[i].shadeSeconds;
                costs_[i].probes += s.costs[i].probes;
                costs_[i].probeFallbacks += s.costs[i].probeFallbacks;
                costs_[i].pointsReplayed += s.costs[i].pointsReplayed;
                s.costs[i] = ObjectFrameCost{};
            }
            stats_.instructions += s.counters.instructions;
            stats_.nonFinite += s.counters.nonFinite;
            s.counters = SurfaceShadingCounters{};
            stats_.shadeParts += s.parts;
            s.parts = {};
        }
        stats_.shadingPoints = stats_.probes = stats_.probeFallbacks = stats_.pointsReplayed = 0;
        for (const ObjectFrameCost& c : costs_) {
            stats_.shadingPoints += c.shadingPoints;
            stats_.probes += c.probes;
            stats_.probeFallbacks += c.probeFallbacks;
            stats_.pointsReplayed += c.pointsReplayed;
        }
    }
    stats_.shadeSeconds += secondsSince(start);
    return all;
}

// 1. The band's shading points, once per frame; 2. each object's points in batches, those
// whose probes found tiles missing staying pending (the band then keeps its points until a later
// pass); 3. once none is pending, the band composited.
void DynamicPhase::shadeBand(size_t band, bool acceptFallbacks, std::vector<TileRequest>& missing) {
    Band::Scratch& s = scratch_->scratch.local();
    const size_t objects = objects_.size();
    if (s.costs.size() != objects) s.costs.assign(objects, ObjectFrameCost{});
    const int row0 = static_cast<int>(band) * options_.bandRows;
    const BandRange range(*layout_, visibility_.layers, row0,
                          std::min(layout_->height(), row0 + options_.bandRows));
    BandInputs& kept = scratch_->inputs[band];
    if (reusing_ && kept.valid() && scratch_->states[band].built) {
        BandPoints& pts = scratch_->states[band];
        s.replay(views_, pts, inputLayout_, kept);
        finishBand(band, range, pts, s.costs, s.parts);
        return;
    }
    // A band keeps points of its own while it waits for tiles, or while the view holds
    // still; otherwise it uses its thread's buffers and keeps nothing.
    BandPoints& pts = scratch_->states[band].built ? scratch_->states[band] : s.work;
    if (!pts.built) {
        const auto began = Clock::now();
        buildBandPoints(*layout_, visibility_, range, objects, pointOptions(), pts, s.points);
        s.parts.points += secondsSince(began);
    }

    s.batchMissed.resize(kBatch);
    s.stillPending.clear();
    bool keep = false;
    if (pts.fresh) {
        if (keeping_) kept.start();
        keep = s.shadeFresh(views_, options_.probe, !acceptFallbacks, pts, missing, inputLayout_,
                            keeping_ ? &kept : nullptr) &&
               keeping_;
        pts.fresh = false;
    } else {
        s.shadePending(views_, options_.probe, !acceptFallbacks, pts, missing);
    }
    pts.pending.swap(s.stillPending);
    if (!pts.pending.empty()) {
        // Shaded again once the missing tiles are filled: the band keeps these buffers.
        if (&pts == &s.work) std::swap(s.work, scratch_->states[band]);
        s.work.built = false;
        return;
    }
    if (keep && (keptBytes_ += kept.bytes()) <= options_.reuseBytes) {
        kept.finish();
        if (&pts == &s.work) std::swap(s.work, scratch_->states[band]);
        s.work.built = false;
        finishBand(band, range, scratch_->states[band], s.costs, s.parts);
        return;
    }
    // Over the budget, or the view moving: the storage goes. A band that found tiles
    // missing keeps it for the next frame's attempt.
    if (keep || !keeping_)
        kept.release();
    else
        kept.invalidate();
    finishBand(band, range, pts, s.costs, s.parts);
    pts.built = false;
    if (&pts != &s.work) std::swap(s.work, pts);  // its buffers go back to the thread
}

void DynamicPhase::finishBand(size_t band, const BandRange& range, const BandPoints& pts,
                              std::vector<ObjectFrameCost>& costs,
                              DynamicFrameStats::ShadeParts& parts) {
    const auto began = Clock::now();
    compositeBand(pts, range, visibility_, layout_->width(), layout_->spp(),
                  scene_.settings.background, samples_.rgba.data(), uniform_.data());
    parts.composite += secondsSince(began);
    for (size_t o = 0; o < objects_.size(); ++o)
        costs[o].shadingPoints += pts.objectStart[o + 1] - pts.objectStart[o];
    bandDone_[band] = 1;
}

void DynamicPhase::resolve(Image& out) {
    stats_.resolveSeconds = resolveAgain(out);
}

double DynamicPhase::resolveAgain(Image& out) {
    const auto start = Clock::now();
    const ScopedSpan span(options_.trace, "resolve", PhaseKind::Resolve, SpanLevel::Phase, -1,
                          frame_->index);
    layout_->resolve(samples_.rgba.data(), uniform_.data(), out,
                     options_.shadingRate == ShadingRate::Quad);
    return secondsSince(start);
}

double DynamicPhase::resolveAgain(Image& out, std::span<const PixelRect> changed) {
    const auto start = Clock::now();
    const ScopedSpan span(options_.trace, "resolve", PhaseKind::Resolve, SpanLevel::Phase, -1,
                          frame_->index);
    layout_->resolveRects(samples_.rgba.data(), uniform_.data(), out,
                          layout_->pixelsReading(changed),
                          options_.shadingRate == ShadingRate::Quad);
    return secondsSince(start);
}

void DynamicPhase::restoreSamples(const KeptSamples& kept) {
    MPSHADE_CHECK(kept.rgba.size() == samples_.rgba.size() &&
                  kept.uniform.size() == uniform_.size());
    std::copy(kept.rgba.begin(), kept.rgba.end(), samples_.rgba.begin());
    std::copy(kept.uniform.begin(), kept.uniform.end(), uniform_.begin());
}

RefineCounts DynamicPhase::refine(std::span<const PixelRect> tiles, const RefinePass& pass,
                                  std::vector<TileRequest>& missing) {
    RefineCounts counts;
    if (stats_.raster.abandoned || !complete() || tiles.empty()) return counts;
    const ScopedSpan span(options_.trace, "refine", PhaseKind::Dynamic, SpanLevel::Phase, -1,
                          frame_->index);
    refineViews_ = views_;
    const float footprint = pass.footprintScale * footprintPixels(pass.rate, layout_->spp());
    const std::span<const float> scales = pass.objectFootprint.empty()
                                              ? std::span<const float>(options_.objectFootprint)
                                              : pass.objectFootprint;
    for (size_t i = 0; i < refineViews_.size(); ++i)
        refineViews_[i].footprintScale = footprint * objectFootprintAt(scales, i);
    const size_t objects = objects_.size();
    // Every worker takes the next tile in order, so the tiles done are a prefix of the list.
    std::atomic<size_t> next{0};
    tbb::enumerable_thread_specific<std::vector<TileRequest>> found;
    const int workers = std::max(1, tbb::this_task_arena::max_concurrency());
    tbb::parallel_for(0, workers, [&](int) {
        enableFlushToZero();  // as shade() does
        Band::Scratch& s = scratch_->refine.local();
        if (s.costs.size() != objects) s.costs.assign(objects, ObjectFrameCost{});
        s.batchMissed.resize(kBatch);
        while (Clock::now() < pass.deadline) {
            const size_t t = next++;
            if (t >= tiles.size()) break;
            const PixelRect& rect = tiles[t];
            const BandRange range(*layout_, visibility_.layers, rect.y0, rect.y1, rect.x0, rect.x1);
            BandPoints& pts = s.work;
            buildBandPoints(*layout_, visibility_, range, objects,
                            {pass.rate, options_.wholePixelShortcut}, pts, s.points);
            s.stillPending.clear();
            s.shadeFresh(refineViews_, options_.probe, false, pts, found.local(), inputLayout_,
                         nullptr);
            pts.built = false;
            compositeBand(pts, range, visibility_, layout_->width(), layout_->spp(),
                          scene_.settings.background, samples_.rgba.data(), uniform_.data());
            for (size_t o = 0; o < objects; ++o)
                s.costs[o].shadingPoints += pts.objectStart[o + 1] - pts.objectStart[o];
        }
    });
    counts.tiles = std::min(next.load(), tiles.size());
    for (Band::Scratch& s : scratch_->refine) {
        for (ObjectFrameCost& c : s.costs) {
            counts.shadingPoints += c.shadingPoints;
            counts.probes += c.probes;
            counts.probeFallbacks += c.probeFallbacks;
            c = ObjectFrameCost{};
        }
        s.parts = {};  // what shadeFresh timed: not the frame's
        s.counters = SurfaceShadingCounters{};
    }
    for (const std::vector<TileRequest>& l : found)
        missing.insert(missing.end(), l.begin(), l.end());
    return counts;
}

}  // namespace mpshade
