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
    const RenderSettings& settings = scene_.settings;
    const RenderOptions o = options.resolved(scene_.settings);
    const FrameState frameState =
        frameStateAt(resources_, frame, o.width, o.height, o.samplesPerPixel);
    const int width = frameState.width, height = frameState.height, spp = frameState.spp;
    const float time = frameState.time;
    const CameraState& camera = frameState.camera;
    const std::vector<ObjectState>& states = frameState.objects;
    const std::vector<ShadingUniforms>& uniforms = frameState.uniforms;
    const WorldRayScene world(resources_, states);

    SampleBuffer samples;
    samples.reset(layouts_.get(width, height, spp, options.seed, options.filter));
    const SampleLayout& layout = *samples.layout;
    const int tile = std::max(1, options.tileSize);
    const int tilesX = (width + tile - 1) / tile, tilesY = (height + tile - 1) / tile;
    const int tileCount = tilesX * tilesY;
    std::atomic<int> tilesDone{0};
    tbb::enumerable_thread_specific<Scratch> scratchPerThread;

    tbb::parallel_for(0, tileCount, [&](int tileIndex) {
        enableFlushToZero();
        Scratch& s = scratchPerThread.local();
        const int x0 = (tileIndex % tilesX) * tile, y0 = (tileIndex / tilesX) * tile;
        const int x1 = std::min(width, x0 + tile), y1 = std::min(height, y0 + tile);
        const int tw = x1 - x0;
        const size_t n = static_cast<size_t>(tw) * (y1 - y0) * spp;
        s.dir.resize(n);
        s.composite.assign(n, SampleComposite{});
        s.active.clear();
        for (int py = y0; py < y1; ++py) {
            for (int px = x0; px < x1; ++px) {
                for (int k = 0; k < spp; ++k) {
                    const size_t local = (static_cast<size_t>(py - y0) * tw + (px - x0)) * spp + k;
                    const size_t global = samples.index(px, py, k);
                    s.dir[local] = camera.direction(layout.x(global), layout.y(global));
                    // Clip to the near and far planes, which are perpendicular to the view axis.
                    const float cosine = glm::dot(s.dir[local], camera.forward);
                    s.active.push_back({static_cast<uint32_t>(local), camera.zNear / cosine,
                                        camera.zFar / cosine});
                }
            }
        }
        RTCIntersectContext ctx;
        for (int layer = 0; layer < options.maxLayers && !s.active.empty(); ++layer) {
            // Trace every pending ray of this layer.
            s.hits.clear();
            for (uint32_t r = 0; r < s.active.size(); ++r) {
                const PendingRay& pr = s.active[r];
                rtcInitIntersectContext(&ctx);
                RTCRayHit rh{};
                const glm::vec3& d = s.dir[pr.sample];
                rh.ray.org_x = camera.eye.x, rh.ray.org_y = camera.eye.y,
                rh.ray.org_z = camera.eye.z;
                rh.ray.dir_x = d.x, rh.ray.dir_y = d.y, rh.ray.dir_z = d.z;
                rh.ray.tnear = pr.tnear;
                rh.ray.tfar = pr.tfar;
                rh.ray.mask = 0xFFFFFFFFu;
                rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
                rtcIntersect1(world.scene(), &ctx, &rh);
                ++s.counters.rays;
                if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
                s.hits.push_back({r, rh.hit.instID[0], rh.hit.geomID, rh.hit.primID, rh.hit.u,
                                  rh.hit.v, rh.ray.tfar});
            }
            // Shade the hits object by object, each object's points as one batch.
            std::sort(s.hits.begin(), s.hits.end(), [](const Hit& a, const Hit& b) {
                return a.object != b.object ? a.object < b.object : a.ray < b.ray;
            });
            s.next.clear();
            for (size_t begin = 0; begin < s.hits.size();) {
                const uint32_t objIndex = s.hits[begin].object;
                size_t end = begin;
                while (end < s.hits.size() && s.hits[end].object == objIndex) ++end;
                const ObjectResources& res = resources_.object(objIndex);
                const ObjectState& st = states[objIndex];
                const SurfaceRayScene& rs = *res.rayScene;
                s.chart.clear();
                s.hitOfPoint.clear();
                s.viewDir.clear();
                for (size_t h = begin; h < end; ++h) {
                    Hit& hit = s.hits[h];
                    const PendingRay& pr = s.active[hit.ray];
                    const glm::vec3 org = glm::vec3(st.worldToObject * glm::vec4(camera.eye, 1.0f));
                    const glm::vec3 dir =
                        glm::vec3(st.worldToObject * glm::vec4(s.dir[pr.sample], 0.0f));
                    SurfaceHit sh;
                    if (!rs.resolveHit(hit.geomID, hit.primID, hit.u, hit.v, hit.t, org, dir, sh))
                        continue;
                    hit.t = sh.t;
                    s.chart.push_back(sh.at);
                    s.hitOfPoint.push_back(static_cast<uint32_t>(h));
                    s.viewDir.push_back(glm::normalize(dir));
                }
                const size_t points = s.chart.size();
                s.geom.resize(points);
                evaluateBatch(rs.surface(), s.chart,
                              std::span<SurfaceSample>(s.geom.data(), points));
                ShadingBatch& batch = s.batch;
                batch.resize(points, 0);
                for (size_t p = 0; p < points; ++p)
                    batch.setPoint(p, s.geom[p], s.chart[p], s.viewDir[p]);
                const ShadingOutputs& out = batch.out;
                ShadingCounters counters;
                res.kernel->run(uniforms[objIndex], batch.in, points, out, s.workspace, counters);
                s.counters.shaderInstructions += counters.instructions;
                s.counters.shadedPoints += counters.points;
                s.counters.occlusionRays += counters.occlusionRays;
                // Composite front to back: C += T * Oi * Ci, T *= 1 - Oi, per channel.
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
                    if (c.transmittance() > 1e-3f) {
                        // Continue behind this surface; the offset is relative to the distance.
                        s.next.push_back({pr.sample, hit.t * (1.0f + 1e-5f) + 1e-6f, pr.tfar});
                    }
                }
                begin = end;
            }
            std::swap(s.active, s.next);
        }
        // Whatever light still passes shows the background.
        for (int py = y0; py < y1; ++py) {
            for (int px = x0; px < x1; ++px) {
                for (int k = 0; k < spp; ++k) {
                    const size_t local = (static_cast<size_t>(py - y0) * tw + (px - x0)) * spp + k;
                    s.composite[local].finish(settings.background,
                                              &samples.rgba[4 * samples.index(px, py, k)]);
                }
            }
        }
        const int done = ++tilesDone;
        if (progress) progress(done, tileCount);
    });

    stats = FrameStats{};
    stats.index = frame;
    stats.time = time;
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
