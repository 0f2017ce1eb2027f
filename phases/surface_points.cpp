#include "phases/surface_points.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <span>
#include <type_traits>

#include <glm/geometric.hpp>

#include "geometry/float4.h"
#include "phases/compositing.h"
#include "phases/phase_trace.h"

namespace mpshade {
namespace {

// Room for n elements without shrinking: scratch shrunk for a small batch would be filled
// with zeros again when the next batch is larger. Elements past n keep whatever they held.
template <typename T>
void growTo(std::vector<T>& v, size_t n) {
    if (v.size() < n) v.resize(n);
}

// Points come in runs on one facet (the samples of a pixel, the pixels of a facet's row):
// scratch.runs holds each run's first point, then n. The steps below take a facet's
// constants once a run and its points four at a time, in vectors whose lanes do exactly
// the scalar arithmetic, in the same order: a point gets the same bits in a lane or done
// alone (a one-point run, or the last of the batch).
// Without a branch: runs of a few points ended in a mispredicted one each (6% of this
// file's time on the courtyard's frame).
std::span<const uint32_t> findRuns(const SurfacePoints& points, std::vector<uint32_t>& runs) {
    const size_t n = points.n;
    growTo(runs, n + 1);
    uint32_t* out = runs.data();
    size_t count = 0;
    for (size_t i = 0; i < n; ++i) {
        out[count] = static_cast<uint32_t>(i);
        count += (i == 0 || points.facet[i] != points.facet[i - 1]) ? 1 : 0;
    }
    out[count++] = static_cast<uint32_t>(n);
    return {out, count};
}

// One facet's constants for step 1, broadcast: a lane type T is float or Float4.
template <typename T>
struct FacetRay {
    T P0[3], e1[3], e2[3], A1[3], A2[3], Dn[3];
    T dxA1, dyA1, dxA2, dyA2, dxDn, dyDn;
};
constexpr size_t kFacetRayRows = 24;  // the floats of a FacetRay<float>, in its order

// The ray through pixel (x, y) has the direction d0 + x dx + y dy. Formed per point and
// then dotted with A1, A2 and Dn: the same products taken as planes in x and y (three
// numbers a facet) cancel near a grazing plane's horizon, and the grazing floor's frames
// had moved from 54.8 to 49.1 dB from the reference's.
template <typename T>
struct ViewRay {
    T d0[3], dx[3], dy[3];
};

template <typename T>
T splatAs(float x) {
    if constexpr (std::is_same_v<T, float>)
        return x;
    else
        return splatFloat4(x);
}

// glm's cross and dot, lane by lane in the same order.
struct Lanes3 {
    Float4 x, y, z;
};
inline Lanes3 crossLanes(const Lanes3& a, const Lanes3& b) {
    return {a.y * b.z - b.y * a.z, a.z * b.x - b.z * a.x, a.x * b.y - b.x * a.y};
}
inline Float4 dotLanes(const glm::vec3& a, const Lanes3& b) {
    return splatFloat4(a.x) * b.x + splatFloat4(a.y) * b.y + splatFloat4(a.z) * b.z;
}

// m[j][i] <- m[i][j].
inline void transpose4(Float4 (&m)[4]) {
    const Float4 t0 = __builtin_shufflevector(m[0], m[1], 0, 4, 1, 5);
    const Float4 t1 = __builtin_shufflevector(m[0], m[1], 2, 6, 3, 7);
    const Float4 t2 = __builtin_shufflevector(m[2], m[3], 0, 4, 1, 5);
    const Float4 t3 = __builtin_shufflevector(m[2], m[3], 2, 6, 3, 7);
    m[0] = __builtin_shufflevector(t0, t2, 0, 1, 4, 5);
    m[1] = __builtin_shufflevector(t0, t2, 2, 3, 6, 7);
    m[2] = __builtin_shufflevector(t1, t3, 0, 1, 4, 5);
    m[3] = __builtin_shufflevector(t1, t3, 2, 3, 6, 7);
}

// Step 1's facet constants of every run, four runs' facets at a time in vector lanes (a
// facet alone, as one point's run had it made, was 200 instructions of scalar arithmetic:
// its corners, three cross products and nine dot products). rays[r * kFacetRayRows ..] is
// run r's FacetRay<float>; rays holds a multiple of 4 runs, at least as many as there are.
void facetRays(const ObjectView& view, const FacetMesh& mesh, const SurfacePoints& points,
               std::span<const uint32_t> runs, float* __restrict rays) {
    const size_t runCount = runs.size() - 1;
    const uint32_t* const positionIndex = mesh.positionIndex.data();
    const FixedPointFormat& format = mesh.format;
    const Float4 ox = splatFloat4(format.origin.x), oy = splatFloat4(format.origin.y),
                 oz = splatFloat4(format.origin.z);
    const Float4 sx = splatFloat4(format.step.x), sy = splatFloat4(format.step.y),
                 sz = splatFloat4(format.step.z);
    const Float4 ex = splatFloat4(view.eye.x), ey = splatFloat4(view.eye.y),
                 ez = splatFloat4(view.eye.z);
    for (size_t r0 = 0; r0 < runCount; r0 += 4) {
        // A facet's indices and corners are read a few runs ahead: points come in object and
        // sample order, so facets are scattered over the mesh, and their first reads had
        // been a tenth of this step's time on the courtyard.
        for (size_t r = r0 + 8; r < std::min(r0 + 12, runCount); ++r) {
            const size_t ahead = 3 * static_cast<size_t>(points.facet[runs[r]]);
            __builtin_prefetch(positionIndex + ahead);
            __builtin_prefetch(mesh.attributeIndex.data() + ahead);  // for steps 3 and 4
        }
        for (size_t r = r0 + 4; r < std::min(r0 + 8, runCount); ++r) {
            const uint32_t* q = positionIndex + 3 * static_cast<size_t>(points.facet[runs[r]]);
            for (int k = 0; k < 3; ++k) {
                __builtin_prefetch(mesh.qx.data() + q[k]);
                __builtin_prefetch(mesh.qy.data() + q[k]);
                __builtin_prefetch(mesh.qz.data() + q[k]);
            }
        }
        alignas(16) float q[3][3][4];  // corner, axis, lane
        for (int j = 0; j < 4; ++j) {
            // Lanes past the last run repeat it.
            const size_t r = std::min(r0 + static_cast<size_t>(j), runCount - 1);
            const uint32_t* p = positionIndex + 3 * static_cast<size_t>(points.facet[runs[r]]);
            for (int v = 0; v < 3; ++v) {
                q[v][0][j] = static_cast<float>(mesh.qx[p[v]]);
                q[v][1][j] = static_cast<float>(mesh.qy[p[v]]);
                q[v][2][j] = static_cast<float>(mesh.qz[p[v]]);
            }
        }
        Lanes3 corner[3];
        for (int v = 0; v < 3; ++v)
            corner[v] = {loadFloat4(q[v][0]), loadFloat4(q[v][1]), loadFloat4(q[v][2])};
        // FixedPointFormat::dequantize: origin + step * q.
        for (Lanes3& c : corner) c = {ox + sx * c.x, oy + sy * c.y, oz + sz * c.z};
        const Lanes3& P0 = corner[0];
        const Lanes3 e1 = {corner[1].x - P0.x, corner[1].y - P0.y, corner[1].z - P0.z};
        const Lanes3 e2 = {corner[2].x - P0.x, corner[2].y - P0.y, corner[2].z - P0.z};
        const Lanes3 tv = {ex - P0.x, ey - P0.y, ez - P0.z};
        // b1 = (d . A1) / (d . Dn), b2 = (d . A2) / (d . Dn): Moller-Trumbore's weights with
        // the triple products rearranged around the direction d.
        const Lanes3 A1 = crossLanes(e2, tv), A2 = crossLanes(tv, e1), Dn = crossLanes(e2, e1);
        const Float4 member[kFacetRayRows] = {P0.x,
                                              P0.y,
                                              P0.z,
                                              e1.x,
                                              e1.y,
                                              e1.z,
                                              e2.x,
                                              e2.y,
                                              e2.z,
                                              A1.x,
                                              A1.y,
                                              A1.z,
                                              A2.x,
                                              A2.y,
                                              A2.z,
                                              Dn.x,
                                              Dn.y,
                                              Dn.z,
                                              dotLanes(view.dx, A1),
                                              dotLanes(view.dy, A1),
                                              dotLanes(view.dx, A2),
                                              dotLanes(view.dy, A2),
                                              dotLanes(view.dx, Dn),
                                              dotLanes(view.dy, Dn)};
        static_assert(kFacetRayRows % 4 == 0);
        // Out run by run (each run's constants together, as FacetRay<float> lays them out):
        // four members at a time, transposed from lanes.
        float* out = rays + r0 * kFacetRayRows;
        for (size_t k = 0; k + 4 <= kFacetRayRows; k += 4) {
            Float4 m[4] = {member[k], member[k + 1], member[k + 2], member[k + 3]};
            transpose4(m);
            for (size_t j = 0; j < 4; ++j) storeFloat4(out + j * kFacetRayRows + k, m[j]);
        }
    }
}

// Run r's FacetRay, broadcast to T.
template <typename T>
FacetRay<T> facetRayOf(const float* rays, size_t r) {
    static_assert(sizeof(FacetRay<float>) == kFacetRayRows * sizeof(float));
    FacetRay<float> f;
    std::memcpy(&f, rays + r * kFacetRayRows, sizeof f);
    if constexpr (std::is_same_v<T, float>) {
        return f;
    } else {
        FacetRay<T> b;
        for (int k = 0; k < 3; ++k) {
            b.P0[k] = splatAs<T>(f.P0[k]), b.e1[k] = splatAs<T>(f.e1[k]);
            b.e2[k] = splatAs<T>(f.e2[k]), b.A1[k] = splatAs<T>(f.A1[k]);
            b.A2[k] = splatAs<T>(f.A2[k]), b.Dn[k] = splatAs<T>(f.Dn[k]);
        }
        b.dxA1 = splatAs<T>(f.dxA1), b.dyA1 = splatAs<T>(f.dyA1);
        b.dxA2 = splatAs<T>(f.dxA2), b.dyA2 = splatAs<T>(f.dyA2);
        b.dxDn = splatAs<T>(f.dxDn), b.dyDn = splatAs<T>(f.dyDn);
        return b;
    }
}

// Step 1 at one point (T float) or four (Float4): the barycentric weights, their screen
// derivatives and P. A ray (nearly) parallel to the facet, or weights that are not finite,
// give the facet's centroid and no derivatives.
template <typename T>
struct RayHit {
    T b1, b2, db1dx, db1dy, db2dx, db2dy, P[3];
};

template <typename T>
RayHit<T> hitFacet(const FacetRay<T>& f, const ViewRay<T>& v, T x, T y) {
    T d[3];
    for (int k = 0; k < 3; ++k) d[k] = v.d0[k] + x * v.dx[k] + y * v.dy[k];
    const T den = d[0] * f.Dn[0] + d[1] * f.Dn[1] + d[2] * f.Dn[2];
    const T tiny = splatAs<T>(1e-30f), one = splatAs<T>(1.0f), zero = splatAs<T>(0.0f);
    const auto big = den > tiny || den < -tiny;
    const T inv = one / (big ? den : one);
    const T c1 = (d[0] * f.A1[0] + d[1] * f.A1[1] + d[2] * f.A1[2]) * inv;
    const T c2 = (d[0] * f.A2[0] + d[1] * f.A2[1] + d[2] * f.A2[2]) * inv;
    // x - x is 0 for a finite x, NaN otherwise.
    const auto ok = big && (c1 - c1 == zero) && (c2 - c2 == zero);
    const T third = splatAs<T>(1.0f / 3.0f);
    RayHit<T> h;
    h.b1 = ok ? c1 : third, h.b2 = ok ? c2 : third;
    h.db1dx = ok ? (f.dxA1 - h.b1 * f.dxDn) * inv : zero;
    h.db1dy = ok ? (f.dyA1 - h.b1 * f.dyDn) * inv : zero;
    h.db2dx = ok ? (f.dxA2 - h.b2 * f.dxDn) * inv : zero;
    h.db2dy = ok ? (f.dyA2 - h.b2 * f.dyDn) * inv : zero;
    for (int k = 0; k < 3; ++k) h.P[k] = f.P0[k] + h.b1 * f.e1[k] + h.b2 * f.e2[k];
    return h;
}

// Step 1: where each point's ray meets its facet: the barycentric weights (and, for a probe,
// their screen derivatives, 4 rows of n) and P.
void intersectFacets(const ObjectView& view, const SurfacePoints& points,
                     std::span<const uint32_t> runs, const float* __restrict rays,
                     float* __restrict bary1, float* __restrict bary2, float* __restrict px,
                     float* __restrict py, float* __restrict pz, float* __restrict derivatives) {
    const size_t n = points.n;
    float* const P[3] = {px, py, pz};
    ViewRay<float> ray;
    ViewRay<Float4> rays4;
    for (int k = 0; k < 3; ++k) {
        ray.d0[k] = view.d0[k], ray.dx[k] = view.dx[k], ray.dy[k] = view.dy[k];
        rays4.d0[k] = splatFloat4(view.d0[k]), rays4.dx[k] = splatFloat4(view.dx[k]);
        rays4.dy[k] = splatFloat4(view.dy[k]);
    }
    const size_t runCount = runs.size() - 1;
    for (size_t r = 0; r < runCount; ++r) {
        const size_t first = runs[r], end = runs[r + 1];
        size_t i = first;
        // Two points or more go four at a time, the last four past the run's end while
        // inside the batch: the next run writes its own points' results over those lanes.
        if (end - first >= 2) {
            const FacetRay<Float4> f = facetRayOf<Float4>(rays, r);
            for (; i < end && i + 4 <= n; i += 4) {
                const RayHit<Float4> h =
                    hitFacet(f, rays4, loadFloat4(points.x + i), loadFloat4(points.y + i));
                storeFloat4(bary1 + i, h.b1), storeFloat4(bary2 + i, h.b2);
                for (int k = 0; k < 3; ++k) storeFloat4(P[k] + i, h.P[k]);
                if (derivatives) {
                    storeFloat4(derivatives + i, h.db1dx);
                    storeFloat4(derivatives + n + i, h.db1dy);
                    storeFloat4(derivatives + 2 * n + i, h.db2dx);
                    storeFloat4(derivatives + 3 * n + i, h.db2dy);
                }
            }
        }
        if (i >= end) continue;
        const FacetRay<float> f = facetRayOf<float>(rays, r);
        for (; i < end; ++i) {
            const RayHit<float> h = hitFacet(f, ray, points.x[i], points.y[i]);
            bary1[i] = h.b1, bary2[i] = h.b2;
            for (int k = 0; k < 3; ++k) P[k][i] = h.P[k];
            if (derivatives) {
                derivatives[i] = h.db1dx, derivatives[n + i] = h.db1dy;
                derivatives[2 * n + i] = h.db2dx, derivatives[3 * n + i] = h.db2dy;
            }
        }
    }
}

// Step 2: I, the unit direction from the eye, with one division (divisions dominated this
// function's profile). A point at the eye takes its ray's direction.
void viewDirections(const ObjectView& view, const SurfacePoints& points, const float* __restrict px,
                    const float* __restrict py, const float* __restrict pz, float* __restrict ix,
                    float* __restrict iy, float* __restrict iz) {
    const size_t n = points.n;
    const float ex = view.eye.x, ey = view.eye.y, ez = view.eye.z;
    const Float4 zero = splatFloat4(0.0f), one = splatFloat4(1.0f);
    const Float4 ex4 = splatFloat4(ex), ey4 = splatFloat4(ey), ez4 = splatFloat4(ez);
    // A direction that came out zero or not finite: the ray's own.
    auto rayDirection = [&](size_t k) {
        const glm::vec3 I = glm::normalize(view.d0 + points.x[k] * view.dx + points.y[k] * view.dy);
        ix[k] = I.x, iy[k] = I.y, iz[k] = I.z;
    };
    size_t i = 0;
    for (; i + 4 <= n; i += 4) {
        const Float4 tx = loadFloat4(px + i) - ex4, ty = loadFloat4(py + i) - ey4,
                     tz = loadFloat4(pz + i) - ez4;
        const Float4 len2 = tx * tx + ty * ty + tz * tz;
        const Float4 inv = one / sqrtFloat4(len2 > zero ? len2 : one);
        const Float4 x = tx * inv, y = ty * inv, z = tz * inv;
        storeFloat4(ix + i, x);
        storeFloat4(iy + i, y);
        storeFloat4(iz + i, z);
        const auto good = x * x + y * y + z * z > zero;
        if (!(good[0] & good[1] & good[2] & good[3]))
            for (size_t k = i; k < i + 4; ++k)
                if (!good[k - i]) rayDirection(k);
    }
    for (; i < n; ++i) {
        const float tx = px[i] - ex, ty = py[i] - ey, tz = pz[i] - ez;
        const float len2 = tx * tx + ty * ty + tz * tz;
        const float inv = 1.0f / std::sqrt(len2 > 0.0f ? len2 : 1.0f);
        ix[i] = tx * inv, iy[i] = ty * inv, iz[i] = tz * inv;
        if (!(ix[i] * ix[i] + iy[i] * iy[i] + iz[i] * iz[i] > 0.0f)) rayDirection(i);
    }
}

// Step 3: a vertex attribute row at each point's weights.
void interpolateRow(const uint32_t* __restrict attributeIndex, const SurfacePoints& points,
                    std::span<const uint32_t> runs, const float* __restrict bary1,
                    const float* __restrict bary2, const float* __restrict r,
                    float* __restrict out) {
    const Float4 one4 = splatFloat4(1.0f);
    const size_t n = points.n;
    for (size_t k = 0; k + 1 < runs.size(); ++k) {
        const size_t first = runs[k], end = runs[k + 1];
        const uint32_t* a = &attributeIndex[3 * static_cast<size_t>(points.facet[first])];
        const float r0 = r[a[0]], r1 = r[a[1]], r2 = r[a[2]];
        size_t i = first;
        const Float4 r04 = splatFloat4(r0), r14 = splatFloat4(r1), r24 = splatFloat4(r2);
        // As in intersectFacets, past the run's end while inside the batch.
        for (; i < end && i + 4 <= n; i += 4) {
            const Float4 b1 = loadFloat4(bary1 + i), b2 = loadFloat4(bary2 + i);
            storeFloat4(out + i, (one4 - b1 - b2) * r04 + b1 * r14 + b2 * r24);
        }
        for (; i < end; ++i) {
            const float b1 = bary1[i], b2 = bary2[i];
            out[i] = (1.0f - b1 - b2) * r0 + b1 * r1 + b2 * r2;
        }
    }
}

// Interpolated normals back to unit length (a zero one stays zero).
void normalizeRows(size_t n, float* __restrict nx, float* __restrict ny, float* __restrict nz) {
    const Float4 zero = splatFloat4(0.0f), one = splatFloat4(1.0f);
    size_t i = 0;
    for (; i + 4 <= n; i += 4) {
        const Float4 x = loadFloat4(nx + i), y = loadFloat4(ny + i), z = loadFloat4(nz + i);
        const Float4 l2 = x * x + y * y + z * z;
        const Float4 inv = l2 > zero ? one / sqrtFloat4(l2 > zero ? l2 : one) : one;
        storeFloat4(nx + i, x * inv);
        storeFloat4(ny + i, y * inv);
        storeFloat4(nz + i, z * inv);
    }
    for (; i < n; ++i) {
        const float l2 = nx[i] * nx[i] + ny[i] * ny[i] + nz[i] * nz[i];
        const float inv = l2 > 0.0f ? 1.0f / std::sqrt(l2 > 0.0f ? l2 : 1.0f) : 1.0f;
        nx[i] *= inv, ny[i] *= inv, nz[i] *= inv;
    }
}

// Step 4, with a shader map: each point's chart point and its footprint (the weights'
// screen derivatives carried to the chart, times footprintScale).
void chartQueries(const ObjectView& view, const FacetMesh& mesh, const SurfacePoints& points,
                  std::span<const uint32_t> runs, const float* __restrict bary1,
                  const float* __restrict bary2, const float* __restrict dd, ProbeQuery* queries) {
    const float s = view.footprintScale;
    const size_t n = points.n;
    const uint32_t* const attributeIndex = mesh.attributeIndex.data();
    for (size_t k = 0; k + 1 < runs.size(); ++k) {
        const size_t first = runs[k], end = runs[k + 1];
        const uint32_t* a = &attributeIndex[3 * static_cast<size_t>(points.facet[first])];
        const ChartPoint& c0 = mesh.attributeChartPoint[a[0]];
        const ChartPoint& c1 = mesh.attributeChartPoint[a[1]];
        const ChartPoint& c2 = mesh.attributeChartPoint[a[2]];
        const float du1 = c1.u - c0.u, du2 = c2.u - c0.u, dv1 = c1.v - c0.v, dv2 = c2.v - c0.v;
        for (size_t i = first; i < end; ++i) {
            const float b1 = bary1[i], b2 = bary2[i];
            const float d0 = dd[i], d1 = dd[n + i], d2 = dd[2 * n + i], d3 = dd[3 * n + i];
            ProbeQuery& q = queries[i];
            q.chart = c0.chart;
            q.u = c0.u + b1 * du1 + b2 * du2;
            q.v = c0.v + b1 * dv1 + b2 * dv2;
            q.dudx = s * (du1 * d0 + du2 * d2);
            q.dudy = s * (du1 * d1 + du2 * d3);
            q.dvdx = s * (dv1 * d0 + dv2 * d2);
            q.dvdy = s * (dv1 * d1 + dv2 * d3);
        }
    }
}

// Step 5: the static n-tuple probed from the map into the batch's channels; the tiles the
// probes found missing added to scratch.missing, sorted and without repeats. Returns how many
// probes found a tile missing when stopping at missing ones (those points marked in `missed`).
size_t probeChannels(const ShaderMap& map, const ProbeOptions& probe, bool stopAtMissing, size_t n,
                     uint8_t* missed, SurfaceShadingScratch& scratch,
                     SurfaceShadingCounters& counters) {
    scratch.reported.resize(8192);
    ProbeResidency residency;
    residency.missing = scratch.reported.data();
    residency.capacity = scratch.reported.size();
    residency.stopAtMissing = stopAtMissing;
    residency.queryMissed = stopAtMissing ? missed : nullptr;
    // Straight into the batch's channel rows, where the dynamic shader reads them.
    probeShaderMap(map, probe, {scratch.queries.data(), n},
                   ProbeOutput{nullptr, scratch.batch.out.channels}, &residency);
    counters.probes += residency.bilinearProbes;
    counters.fallbacks += residency.fallbacks;
    counters.missingProbes += residency.missingProbes;
    if (residency.count > 0) {
        auto packedLess = [](const TileKey& x, const TileKey& y) {
            return x.packed() < y.packed();
        };
        const auto first = scratch.reported.begin();
        const auto last = first + static_cast<std::ptrdiff_t>(residency.count);
        std::sort(first, last, packedLess);
        const auto end = std::unique(first, last);
        for (auto it = first; it != end; ++it)
            if (scratch.missing.empty() || !(scratch.missing.back() == *it))
                scratch.missing.push_back(*it);
    }
    return stopAtMissing ? residency.missingProbes : 0;
}

}  // namespace

void runDynamicShader(const ObjectView& view, const ShadingInputs& in, size_t n, float* color,
                      float* opacity, SurfaceShadingScratch& scratch,
                      SurfaceShadingCounters& counters) {
    const auto began = std::chrono::steady_clock::now();
    ShadingBatch& batch = scratch.batch;
    ShadingCounters shading;
    view.rep->dynamicKernel->run(*view.uniforms, in, n, batch.out, scratch.workspace, shading);
    counters.instructions += shading.instructions;
    const uint64_t nonFinite = sanitizeShadeRows(n, batch.out.Ci, batch.out.Oi, color, opacity);
    counters.nonFinite += nonFinite;
    counters.kernelSeconds += secondsSince(began);
}

std::vector<int> shadingInputRows(const ObjectRepresentation& rep) {
    std::vector<int> rows = {ShadingBatch::P, ShadingBatch::P + 1, ShadingBatch::P + 2,
                             ShadingBatch::I, ShadingBatch::I + 1, ShadingBatch::I + 2};
    for (int row : rep.geometryRows) rows.push_back(row < VertexAttributes::U ? row : row + 3);
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    return rows;
}

size_t shadingChannels(const ObjectRepresentation& rep) {
    return rep.map ? static_cast<size_t>(rep.map->channels())
                   : static_cast<size_t>(rep.mesh.channels);
}

// Steps 1-5 fill the dynamic shader's inputs; step 6 runs it and makes its results finite.
size_t shadeSurfacePoints(const ObjectView& view, const ProbeOptions& probe, bool stopAtMissing,
                          const SurfacePoints& points, float* color, float* opacity,
                          uint8_t* missed, SurfaceShadingScratch& scratch,
                          SurfaceShadingCounters& counters) {
    const auto began = std::chrono::steady_clock::now();
    const ObjectRepresentation& rep = *view.rep;
    const FacetMesh& mesh = rep.mesh;
    const VertexAttributes& attr = mesh.attributes;
    const bool useMap = rep.map != nullptr;
    const size_t n = points.n;
    const size_t channels = shadingChannels(rep);
    ShadingBatch& batch = scratch.batch;
    batch.resize(n, channels);
    if (useMap) growTo(scratch.queries, n);
    float* rows[ShadingBatch::kInputRows];
    for (int r = 0; r < ShadingBatch::kInputRows; ++r) rows[r] = batch.row(r);
    growTo(scratch.b1, n), growTo(scratch.b2, n);
    if (useMap) growTo(scratch.derivatives, 4 * n);
    const float* bary1 = scratch.b1.data();
    const float* bary2 = scratch.b2.data();
    const float* px = rows[ShadingBatch::P];
    const float* py = rows[ShadingBatch::P + 1];
    const float* pz = rows[ShadingBatch::P + 2];

    const std::span<const uint32_t> runs = findRuns(points, scratch.runs);
    growTo(scratch.facetRays, kFacetRayRows * ((runs.size() - 1 + 3) / 4 * 4));
    facetRays(view, mesh, points, runs, scratch.facetRays.data());
    intersectFacets(view, points, runs, scratch.facetRays.data(), scratch.b1.data(),
                    scratch.b2.data(), rows[ShadingBatch::P], rows[ShadingBatch::P + 1],
                    rows[ShadingBatch::P + 2], useMap ? scratch.derivatives.data() : nullptr);
    viewDirections(view, points, px, py, pz, rows[ShadingBatch::I], rows[ShadingBatch::I + 1],
                   rows[ShadingBatch::I + 2]);
    const uint32_t* const attributeIndex = mesh.attributeIndex.data();
    for (int row : rep.geometryRows)
        interpolateRow(attributeIndex, points, runs, bary1, bary2,
                       attr.rows[static_cast<size_t>(row)].data(),
                       rows[row < VertexAttributes::U ? row : row + 3]);
    if (!attr.rows[VertexAttributes::Nx].empty())
        normalizeRows(n, rows[ShadingBatch::N], rows[ShadingBatch::N + 1],
                      rows[ShadingBatch::N + 2]);
    if (useMap) {
        chartQueries(view, mesh, points, runs, bary1, bary2, scratch.derivatives.data(),
                     scratch.queries.data());
    } else {
        for (size_t c = 0; c < channels; ++c)
            interpolateRow(attributeIndex, points, runs, bary1, bary2,
                           attr.rows[VertexAttributes::kGeometryRows + c].data(), batch.channel(c));
    }
    if (stopAtMissing && missed) std::fill(missed, missed + n, uint8_t{0});
    const auto interpolated = std::chrono::steady_clock::now();
    counters.interpolateSeconds += std::chrono::duration<double>(interpolated - began).count();
    size_t missedCount = 0;
    if (useMap && channels > 0) {
        missedCount = probeChannels(*rep.map, probe, stopAtMissing, n, missed, scratch, counters);
        counters.probeSeconds += secondsSince(interpolated);
    }

    if (missedCount > 0) {
        missedCount = 0;
        for (size_t i = 0; i < n; ++i) missedCount += missed[i];
    }
    // Every point waits for a tile (a run's first frame): its results would be thrown away.
    if (stopAtMissing && missedCount == n && n > 0) {
        std::fill(color, color + 3 * n, 0.0f);
        std::fill(opacity, opacity + 3 * n, 0.0f);
        return missedCount;
    }
    runDynamicShader(view, batch.in, n, color, opacity, scratch, counters);
    return missedCount;
}

}  // namespace mpshade
