#include "phases/reference_renderer.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <glm/geometric.hpp>

#include "phases/compositing.h"
#include "shading/shading_batch.h"

namespace mpshade {
namespace {

struct PendingRay {
    uint32_t sample;  // index into the tile's sample arrays
    float tnear, tfar;
};

struct Hit {
    uint32_t ray;  // index into the pending rays
    uint32_t object;
    unsigned geomID, primID;
    float u, v, t;
};

// Per-thread scratch, reused across tiles so the hot loops never allocate once warm.
struct Scratch {
    std::vector<glm::vec3> dir;              // per tile sample, world space
    std::vector<SampleComposite> composite;  // per tile sample
    std::vector<PendingRay> active, next;
    std::vector<Hit> hits;
    std::vector<ChartPoint> chart;
    std::vector<SurfaceSample> geom;
    std::vector<uint32_t> hitOfPoint;
    std::vector<glm::vec3> viewDir;  // per point: unit ray direction, object space
    ShadingBatch batch;
    std::vector<float> workspace;  // interpreter registers
    FrameStats counters;
};

// Pixels [x0, x1) x [y0, y1) of the frame.
struct TileRect {
    int x0, y0, x1, y1;
};

// One frame's tiles, each traced layer by layer: every pending ray of a layer traced, the
// hits shaded object by object (each object's points as one batch), and the rays that
// still pass light continued behind their surface.
class TileTracer {
  public:
    TileTracer(const SceneResources& resources, const FrameState& frame, const WorldRayScene& world,
               SampleBuffer& samples, int maxLayers, const glm::vec3& background)
        : resources_(resources),
          frame_(frame),
          world_(world),
          samples_(samples),
          layout_(*samples.layout),
          maxLayers_(maxLayers),
          background_(background) {}

    void trace(const TileRect& r, Scratch& s) const {
        startRays(r, s);
        for (int layer = 0; layer < maxLayers_ && !s.active.empty(); ++layer) {
            traceLayer(s);
            std::sort(s.hits.begin(), s.hits.end(), [](const Hit& a, const Hit& b) {
                return a.object != b.object ? a.object < b.object : a.ray < b.ray;
            });
            s.next.clear();
            for (size_t begin = 0; begin < s.hits.size();) {
                size_t end = begin;
                while (end < s.hits.size() && s.hits[end].object == s.hits[begin].object) ++end;
                shadeHits(begin, end, s);
                begin = end;
            }
            std::swap(s.active, s.next);
        }
        // Whatever light still passes shows the background.
        forEachSample(r, [&](size_t local, size_t global) {
            s.composite[local].finish(background_, &samples_.rgba[4 * global]);
        });
    }

  private:
    // Calls f(index in the tile, index in the frame) for every sample of the tile.
    template <typename F>
    void forEachSample(const TileRect& r, F&& f) const {
        const int spp = layout_.spp(), tw = r.x1 - r.x0;
        for (int py = r.y0; py < r.y1; ++py)
            for (int px = r.x0; px < r.x1; ++px)
                for (int k = 0; k < spp; ++k)
                    f((static_cast<size_t>(py - r.y0) * tw + (px - r.x0)) * spp + k,
                      samples_.index(px, py, k));
    }

    // A camera ray per sample, clipped to the near and far planes (perpendicular to the
    // view axis).
    void startRays(const TileRect& r, Scratch& s) const {
        const CameraState& camera = frame_.camera;
        const size_t n = static_cast<size_t>(r.x1 - r.x0) * (r.y1 - r.y0) * layout_.spp();
        s.dir.resize(n);
        s.composite.assign(n, SampleComposite{});
        s.active.clear();
        forEachSample(r, [&](size_t local, size_t global) {
            s.dir[local] = camera.direction(layout_.x(global), layout_.y(global));
            const float cosine = glm::dot(s.dir[local], camera.forward);
            s.active.push_back(
                {static_cast<uint32_t>(local), camera.zNear / cosine, camera.zFar / cosine});
        });
    }

    void traceLayer(Scratch& s) const {
        const CameraState& camera = frame_.camera;
        RTCIntersectContext ctx;
        s.hits.clear();
        for (uint32_t r = 0; r < s.active.size(); ++r) {
            const PendingRay& pr = s.active[r];
            rtcInitIntersectContext(&ctx);
            RTCRayHit rh{};
            const glm::vec3& d = s.dir[pr.sample];
            rh.ray.org_x = camera.eye.x, rh.ray.org_y = camera.eye.y, rh.ray.org_z = camera.eye.z;
            rh.ray.dir_x = d.x, rh.ray.dir_y = d.y, rh.ray.dir_z = d.z;
            rh.ray.tnear = pr.tnear;
            rh.ray.tfar = pr.tfar;
            rh.ray.mask = 0xFFFFFFFFu;
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(world_.scene(), &ctx, &rh);
            ++s.counters.rays;
            if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
            s.hits.push_back({r, rh.hit.instID[0], rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v,
                              rh.ray.tfar});
        }
    }

    // Hits [begin, end), all of one object: resolved on its exact surface, shaded with the
    // whole shader, and composited front to back (C += T * Oi * Ci, T *= 1 - Oi, per
    // channel).
    void shadeHits(size_t begin, size_t end, Scratch& s) const {
        const uint32_t objIndex = s.hits[begin].object;
        const ObjectResources& res = resources_.object(objIndex);
        const ObjectState& st = frame_.objects[objIndex];
        const SurfaceRayScene& rs = *res.rayScene;
        s.chart.clear();
        s.hitOfPoint.clear();
        s.viewDir.clear();
        const glm::vec3 org = glm::vec3(st.worldToObject * glm::vec4(frame_.camera.eye, 1.0f));
        for (size_t h = begin; h < end; ++h) {
            Hit& hit = s.hits[h];
            const glm::vec3 dir =
                glm::vec3(st.worldToObject * glm::vec4(s.dir[s.active[hit.ray].sample], 0.0f));
            SurfaceHit sh;
            if (!rs.resolveHit(hit.geomID, hit.primID, hit.u, hit.v, hit.t, org, dir, sh)) continue;
            hit.t = sh.t;
            s.chart.push_back(sh.at);
            s.hitOfPoint.push_back(static_cast<uint32_t>(h));
            s.viewDir.push_back(glm::normalize(dir));
        }
        const size_t points = s.chart.size();
        s.geom.resize(points);
        evaluateBatch(rs.surface(), s.chart, std::span<SurfaceSample>(s.geom.data(), points));
        ShadingBatch& batch = s.batch;
        batch.resize(points, 0);
        for (size_t p = 0; p < points; ++p) batch.setPoint(p, s.geom[p], s.chart[p], s.viewDir[p]);
        const ShadingOutputs& out = batch.out;
        ShadingCounters counters;
        res.kernel->run(frame_.uniforms[objIndex], batch.in, points, out, s.workspace, counters);
        s.counters.shaderInstructions += counters.instructions;
        s.counters.shadedPoints += counters.points;
        s.counters.occlusionRays += counters.occlusionRays;
        for (size_t p = 0; p < points; ++p) {
            const Hit& hit = s.hits[s.hitOfPoint[p]];
            const PendingRay& pr = s.active[hit.ray];
            float ci[3], oi[3];
            for (int k = 0; k < 3; ++k) {
                ci[k] = out.Ci[k][p];
                oi[k] = out.Oi[k][p];
            }
            if (!sanitizeShade(ci, oi)) ++s.counters.nonFiniteSamples;
            SampleComposite& c = s.composite[pr.sample];
            c.over(ci, oi);
            // Continue behind this surface; the offset is relative to the distance.
            if (c.transmittance() > 1e-3f)
                s.next.push_back({pr.sample, hit.t * (1.0f + 1e-5f) + 1e-6f, pr.tfar});
        }
    }

    const SceneResources& resources_;
    const FrameState& frame_;
    const WorldRayScene& world_;
    SampleBuffer& samples_;
    const SampleLayout& layout_;
    const int maxLayers_;
    const glm::vec3 background_;
};

}  // namespace

ReferenceRenderer::ReferenceRenderer(const Scene& scene) : scene_(scene), resources_(scene) {}

void ReferenceRenderer::renderFrame(int frame, const RenderOptions& options, FrameStats& stats,
                                    Image& image, const ProgressFn& progress) {
    const SampleBuffer samples = renderSamples(frame, options, stats, progress);
    const auto start = std::chrono::steady_clock::now();
    samples.layout->resolve(samples.rgba.data(), nullptr, image);
    stats.wallSeconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

SampleBuffer ReferenceRenderer::renderSamples(int frame, const RenderOptions& options,
                                              FrameStats& stats, const ProgressFn& progress) {
    const auto start = std::chrono::steady_clock::now();
    const RenderOptions o = options.resolved(scene_.settings);
    const FrameState frameState =
        frameStateAt(resources_, frame, o.width, o.height, o.samplesPerPixel);
    const int width = frameState.width, height = frameState.height, spp = frameState.spp;
    const WorldRayScene world(resources_, frameState.objects);
    SampleBuffer samples;
    samples.reset(layouts_.get(width, height, spp, options.seed, options.filter));
    const TileTracer tracer(resources_, frameState, world, samples, options.maxLayers,
                            scene_.settings.background);
    const int tile = std::max(1, options.tileSize);
    const int tilesX = (width + tile - 1) / tile, tilesY = (height + tile - 1) / tile;
    const int tileCount = tilesX * tilesY;
    std::atomic<int> tilesDone{0};
    tbb::enumerable_thread_specific<Scratch> scratchPerThread;
    tbb::parallel_for(0, tileCount, [&](int tileIndex) {
        enableFlushToZero();
        const int x0 = (tileIndex % tilesX) * tile, y0 = (tileIndex / tilesX) * tile;
        tracer.trace({x0, y0, std::min(width, x0 + tile), std::min(height, y0 + tile)},
                     scratchPerThread.local());
        const int done = ++tilesDone;
        if (progress) progress(done, tileCount);
    });

    stats = FrameStats{};
    stats.index = frame;
    stats.time = frameState.time;
    stats.samples = static_cast<uint64_t>(width) * height * spp;
    for (const Scratch& s : scratchPerThread) {
        stats.rays += s.counters.rays;
        stats.occlusionRays += s.counters.occlusionRays;
        stats.shadedPoints += s.counters.shadedPoints;
        stats.shaderInstructions += s.counters.shaderInstructions;
        stats.nonFiniteSamples += s.counters.nonFiniteSamples;
    }
    stats.wallSeconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return samples;
}

}  // namespace mpshade
