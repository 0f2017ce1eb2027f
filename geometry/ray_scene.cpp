#include "geometry/ray_scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <pmmintrin.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <xmmintrin.h>
#include <glm/geometric.hpp>

#include "geometry/error.h"

namespace mpshade {
namespace {

void embreeError(void*, RTCError code, const char* message) {
    std::fprintf(stderr, "mpshade: Embree error %d: %s\n", static_cast<int>(code),
                 message ? message : "");
}

// Solves the 3x3 system [a b c] x = r by Cramer's rule; false when singular.
bool solve3(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& r,
            glm::dvec3& x) {
    const double det = glm::dot(a, glm::cross(b, c));
    const double scale = glm::length(a) * glm::length(b) * glm::length(c);
    if (!(std::fabs(det) > 1e-10 * scale)) return false;
    x.x = glm::dot(r, glm::cross(b, c)) / det;
    x.y = glm::dot(a, glm::cross(r, c)) / det;
    x.z = glm::dot(a, glm::cross(b, r)) / det;
    return true;
}

}  // namespace

RTCDevice embreeDevice() {
    static RTCDevice device = [] {
        RTCDevice d = rtcNewDevice(nullptr);
        MPSHADE_CHECK(d != nullptr);
        rtcSetDeviceErrorFunction(d, embreeError, nullptr);
        return d;
    }();
    return device;
}

void enableFlushToZero() {
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
}

namespace {

unsigned attachDiscs(RTCDevice device, RTCScene scene, const PointCloud& cloud) {
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_ORIENTED_DISC_POINT);
    const size_t n = cloud.centers.size();
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0,
                                                          RTC_FORMAT_FLOAT4, 4 * sizeof(float), n));
    auto* nb = static_cast<float*>(rtcSetNewGeometryBuffer(
        geom, RTC_BUFFER_TYPE_NORMAL, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), n));
    for (size_t k = 0; k < n; ++k) {
        v[4 * k + 0] = cloud.centers[k].x;
        v[4 * k + 1] = cloud.centers[k].y;
        v[4 * k + 2] = cloud.centers[k].z;
        v[4 * k + 3] = cloud.radii[k];
        nb[3 * k + 0] = cloud.normals[k].x;
        nb[3 * k + 1] = cloud.normals[k].y;
        nb[3 * k + 2] = cloud.normals[k].z;
    }
    rtcCommitGeometry(geom);
    const unsigned id = rtcAttachGeometry(scene, geom);
    rtcReleaseGeometry(geom);
    return id;
}

}  // namespace

// A grid of (rate + 1)^2 exact surface points per chart, two triangles per cell; the
// charts evaluated in parallel, each into its own slice, so the result does not depend on
// the threads.
unsigned SurfaceRayScene::attachTessellation(RTCDevice device) const {
    const int charts = chartCount(surface_);
    std::vector<int> rates(static_cast<size_t>(charts));
    std::vector<size_t> firstVertex(static_cast<size_t>(charts) + 1, 0);
    for (int chart = 0; chart < charts; ++chart) {
        rates[static_cast<size_t>(chart)] =
            std::visit([&](const auto& s) { return s.tessellationRate(chart); }, surface_);
        const size_t row = static_cast<size_t>(rates[static_cast<size_t>(chart)]) + 1;
        firstVertex[static_cast<size_t>(chart) + 1] =
            firstVertex[static_cast<size_t>(chart)] + row * row;
    }
    const size_t nv = firstVertex.back();
    std::vector<float> positions(3 * nv);
    vertexUV_.assign(2 * nv, 0.0f);
    tbb::parallel_for(0, charts, [&](int chart) {
        const int rate = rates[static_cast<size_t>(chart)];
        size_t at = firstVertex[static_cast<size_t>(chart)];
        for (int j = 0; j <= rate; ++j)
            for (int i = 0; i <= rate; ++i, ++at) {
                const float u = static_cast<float>(i) / rate, v = static_cast<float>(j) / rate;
                const glm::vec3 p = evaluate(surface_, {chart, u, v}).P;
                positions[3 * at] = p.x, positions[3 * at + 1] = p.y, positions[3 * at + 2] = p.z;
                vertexUV_[2 * at] = u, vertexUV_[2 * at + 1] = v;
            }
    });
    for (int chart = 0; chart < charts; ++chart) {
        const unsigned rate = static_cast<unsigned>(rates[static_cast<size_t>(chart)]);
        const unsigned base = static_cast<unsigned>(firstVertex[static_cast<size_t>(chart)]);
        const unsigned row = rate + 1;
        for (unsigned j = 0; j < rate; ++j)
            for (unsigned i = 0; i < rate; ++i) {
                const unsigned a = base + j * row + i, b = a + 1, c = a + row + 1, d = a + row;
                triIndex_.insert(triIndex_.end(), {a, b, c, a, c, d});
                triChart_.insert(triChart_.end(), {chart, chart});
            }
    }
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    const size_t nt = triChart_.size();
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
        geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv));
    std::copy(positions.begin(), positions.end(), vb);
    auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
        geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), nt));
    std::copy(triIndex_.begin(), triIndex_.end(), ib);
    rtcCommitGeometry(geom);
    const unsigned id = rtcAttachGeometry(scene_, geom);
    rtcReleaseGeometry(geom);
    return id;
}

SurfaceRayScene::SurfaceRayScene(const Surface& surface) : surface_(surface) {}

// Within an isolated arena: while the charts' parallel loop waits, this thread runs only
// its own tasks, never an outer one that could ask for this scene again (call_once is not
// reentrant).
void SurfaceRayScene::buildNow() const {
    tbb::this_task_arena::isolate([this] {
        RTCDevice device = embreeDevice();
        scene_ = rtcNewScene(device);
        rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
        if (const auto* cloud = std::get_if<PointCloud>(&surface_))
            discGeom_ = attachDiscs(device, scene_, *cloud);
        else
            triGeom_ = attachTessellation(device);
        rtcCommitScene(scene_);
    });
    builtFlag_.store(true, std::memory_order_release);
}

SurfaceRayScene::~SurfaceRayScene() {
    if (scene_) rtcReleaseScene(scene_);
}

bool SurfaceRayScene::resolveHit(unsigned geomID, unsigned primID, float bu, float bv, float tHit,
                                 const glm::vec3& org, const glm::vec3& dir,
                                 SurfaceHit& hit) const {
    build();
    if (geomID == discGeom_) {
        const auto& cloud = std::get<PointCloud>(surface_);
        hit.at = cloud.chartPointOf(static_cast<int>(primID), org + tHit * dir);
        hit.t = tHit;
        hit.refined = true;  // a disc is flat: the Embree hit is exact
        return true;
    }
    const unsigned* tri = &triIndex_[3 * static_cast<size_t>(primID)];
    const float w0 = 1.0f - bu - bv;
    ChartPoint at{
        triChart_[primID],
        w0 * vertexUV_[2 * tri[0]] + bu * vertexUV_[2 * tri[1]] + bv * vertexUV_[2 * tri[2]],
        w0 * vertexUV_[2 * tri[0] + 1] + bu * vertexUV_[2 * tri[1] + 1] +
            bv * vertexUV_[2 * tri[2] + 1]};
    at.u = std::fmin(std::fmax(at.u, 0.0f), 1.0f);
    at.v = std::fmin(std::fmax(at.v, 0.0f), 1.0f);

    // Newton iteration on F(u, v, t) = P(u, v) - (org + t dir) = 0, in double precision.
    const glm::dvec3 o(org), d(dir);
    double u = at.u, v = at.v, t = tHit;
    bool converged = false;
    int clampedSteps = 0;
    for (int iter = 0; iter < 10; ++iter) {
        const SurfaceSample s =
            evaluate(surface_, {at.chart, static_cast<float>(u), static_cast<float>(v)});
        const glm::dvec3 residual = glm::dvec3(s.P) - (o + t * d);
        const double scale =
            std::fmax(glm::length(glm::dvec3(s.P)), 1e-30) + std::fabs(t) * glm::length(d);
        if (glm::length(residual) <= 1e-6 * scale) {
            converged = true;
            break;
        }
        glm::dvec3 step;
        if (!solve3(glm::dvec3(s.dPdu), glm::dvec3(s.dPdv), -d, -residual, step)) break;
        u += step.x;
        v += step.y;
        t += step.z;
        if (!std::isfinite(u + v + t)) break;
        // A step may overshoot the chart; clamp and go on. If the true hit lies in a
        // neighbouring chart the iteration stalls on the edge and the tessellation's
        // answer is kept.
        const bool outside = u < 0.0 || u > 1.0 || v < 0.0 || v > 1.0;
        u = std::fmin(std::fmax(u, 0.0), 1.0);
        v = std::fmin(std::fmax(v, 0.0), 1.0);
        if (outside && ++clampedSteps > 3) break;
    }
    if (converged) {
        hit.at = {at.chart, static_cast<float>(u), static_cast<float>(v)};
        hit.t = static_cast<float>(t);
        hit.refined = true;
    } else {
        // Keep the tessellation's chart point and put the hit on the surface there.
        const glm::vec3 p = evaluate(surface_, at).P;
        hit.at = at;
        hit.t = glm::dot(p - org, dir) / glm::dot(dir, dir);
        hit.refined = false;
    }
    return std::isfinite(hit.t);
}

bool SurfaceRayScene::intersect(const glm::vec3& org, const glm::vec3& dir, float tnear, float tfar,
                                SurfaceHit& hit) const {
    build();
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh{};
    rh.ray.org_x = org.x, rh.ray.org_y = org.y, rh.ray.org_z = org.z;
    rh.ray.dir_x = dir.x, rh.ray.dir_y = dir.y, rh.ray.dir_z = dir.z;
    rh.ray.tnear = tnear;
    rh.ray.tfar = tfar;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    return resolveHit(rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v, rh.ray.tfar, org, dir, hit);
}

bool SurfaceRayScene::escapes(const glm::vec3& org, const glm::vec3& dir) const {
    if (std::holds_alternative<Plane>(surface_))
        return (org.y > 0.0f && dir.y >= 0.0f) || (org.y < 0.0f && dir.y <= 0.0f);
    if (const auto* sphere = std::get_if<Sphere>(&surface_)) {
        // The tessellation's vertices are radius * a unit vector rounded to float: within a
        // few parts in 10^7 of the radius. 1e-5 keeps the test far from that.
        const float r = sphere->radius;
        return glm::dot(org, dir) >= 0.0f && glm::dot(org, org) > r * r * (1.0f + 1e-5f);
    }
    return false;
}

void SurfaceRayScene::occluded(const float* const org[3], const float* const dir[3],
                               const uint8_t* active, int n, float tnear, float tfar,
                               uint8_t* blocked) const {
    build();
    constexpr int kStream = 64;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    const bool fromOrigin = tnear >= 0.0f;  // escapes() speaks of t >= 0
    alignas(16) RTCRay rays[kStream];
    bool traced[kStream];
    for (int first = 0; first < n; first += kStream) {
        const int count = std::min(kStream, n - first);
        int tracing = 0;
        for (int k = 0; k < count; ++k) {
            const int i = first + k;
            const glm::vec3 o(org[0][i], org[1][i], org[2][i]), d(dir[0][i], dir[1][i], dir[2][i]);
            traced[k] = (!active || active[i]) && !(fromOrigin && escapes(o, d));
            tracing += traced[k] ? 1 : 0;
            RTCRay& ray = rays[k];
            ray = RTCRay{};
            ray.org_x = o.x, ray.org_y = o.y, ray.org_z = o.z;
            ray.dir_x = d.x, ray.dir_y = d.y, ray.dir_z = d.z;
            // Not traced: tnear above tfar (Embree's rule for streams).
            ray.tnear = traced[k] ? tnear : 1.0f;
            ray.tfar = traced[k] ? tfar : 0.0f;
            ray.mask = 0xFFFFFFFFu;
        }
        if (tracing > 0)
            rtcOccluded1M(scene_, &ctx, rays, static_cast<unsigned>(count), sizeof(RTCRay));
        for (int k = 0; k < count; ++k)
            blocked[first + k] = traced[k] && rays[k].tfar < 0.0f ? 1 : 0;
    }
}

}  // namespace mpshade
