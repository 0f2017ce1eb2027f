#include "phases/surface_points.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <glm/geometric.hpp>

#include "geometry/float4.h"
#include "phases/compositing.h"
#include "phases/phase_trace.h"

namespace mpshade {
namespace {

// Step 1: where each point's ray meets its facet: the barycentric weights (and, for a probe,
// their screen derivatives, 4 per point) and P. Per facet (consecutive points mostly share
// one: the samples of a pixel, the pixels of a facet): its corners and the rearranged triple
// products. The loops after this one have no branch on the facet and vectorize.
void intersectFacets(const ObjectView& view, const FacetMesh& mesh, const SurfacePoints& points,
                     float* __restrict bary1, float* __restrict bary2, float* __restrict px,
                     float* __restrict py, float* __restrict pz, float* __restrict derivatives) {
    size_t facet = ~size_t{0};
    glm::vec3 P0(0.0f), e1(0.0f), e2(0.0f), A1(0.0f), A2(0.0f), Dn(0.0f);
    float dxA1 = 0.0f, dyA1 = 0.0f, dxA2 = 0.0f, dyA2 = 0.0f, dxDn = 0.0f, dyDn = 0.0f;
    for (size_t i = 0; i < points.n; ++i) {
        if (points.facet[i] != facet) {
            facet = points.facet[i];
            const uint32_t* p = &mesh.positionIndex[3 * facet];
            P0 = mesh.format.dequantize(mesh.qx[p[0]], mesh.qy[p[0]], mesh.qz[p[0]]);
            e1 = mesh.format.dequantize(mesh.qx[p[1]], mesh.qy[p[1]], mesh.qz[p[1]]) - P0;
            e2 = mesh.format.dequantize(mesh.qx[p[2]], mesh.qy[p[2]], mesh.qz[p[2]]) - P0;
            const glm::vec3 tv = view.eye - P0;
            // b1 = (d . A1) / (d . Dn), b2 = (d . A2) / (d . Dn): Moller-Trumbore's weights
            // with the triple products rearranged around the direction d.
            A1 = glm::cross(e2, tv), A2 = glm::cross(tv, e1), Dn = glm::cross(e2, e1);
            dxA1 = glm::dot(view.dx, A1), dyA1 = glm::dot(view.dy, A1);
            dxA2 = glm::dot(view.dx, A2), dyA2 = glm::dot(view.dy, A2);
            dxDn = glm::dot(view.dx, Dn), dyDn = glm::dot(view.dy, Dn);
        }
        const glm::vec3 d = view.d0 + points.x[i] * view.dx + points.y[i] * view.dy;
        const float den = glm::dot(d, Dn);
        float b1 = 1.0f / 3.0f, b2 = 1.0f / 3.0f;
        float db1dx = 0.0f, db1dy = 0.0f, db2dx = 0.0f, db2dy = 0.0f;
        if (std::fabs(den) > 1e-30f) {
            const float inv = 1.0f / den;
            const float c1 = glm::dot(d, A1) * inv, c2 = glm::dot(d, A2) * inv;
            if (std::isfinite(c1) && std::isfinite(c2)) {
                b1 = c1, b2 = c2;
                db1dx = (dxA1 - b1 * dxDn) * inv;
                db1dy = (dyA1 - b1 * dyDn) * inv;
                db2dx = (dxA2 - b2 * dxDn) * inv;
                db2dy = (dyA2 - b2 * dyDn) * inv;
            }
        }
        bary1[i] = b1, bary2[i] = b2;
        const glm::vec3 P = P0 + b1 * e1 + b2 * e2;
        px[i] = P.x, py[i] = P.y, pz[i] = P.z;
        if (derivatives) {
            float* dd = &derivatives[4 * i];
            dd[0] = db1dx, dd[1] = db1dy, dd[2] = db2dx, dd[3] = db2dy;
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
    size_t i = 0;
    for (; i + 4 <= n; i += 4) {
        const Float4 tx = loadFloat4(px + i) - ex4, ty = loadFloat4(py + i) - ey4,
                     tz = loadFloat4(pz + i) - ez4;
        const Float4 len2 = tx * tx + ty * ty + tz * tz;
        const Float4 inv = one / sqrtFloat4(len2 > zero ? len2 : one);
        storeFloat4(ix + i, tx * inv);
        storeFloat4(iy + i, ty * inv);
        storeFloat4(iz + i, tz * inv);
    }
    for (; i < n; ++i) {
        const float tx = px[i] - ex, ty = py[i] - ey, tz = pz[i] - ez;
        const float len2 = tx * tx + ty * ty + tz * tz;
        const float inv = 1.0f / std::sqrt(len2 > 0.0f ? len2 : 1.0f);
        ix[i] = tx * inv, iy[i] = ty * inv, iz[i] = tz * inv;
    }
    for (size_t k = 0; k < n; ++k)
        if (!(ix[k] * ix[k] + iy[k] * iy[k] + iz[k] * iz[k] > 0.0f)) {
            const glm::vec3 I =
                glm::normalize(view.d0 + points.x[k] * view.dx + points.y[k] * view.dy);
            ix[k] = I.x, iy[k] = I.y, iz[k] = I.z;
        }
}

// Step 3: a vertex attribute row at each point's weights.
void interpolateRow(const uint32_t* __restrict attributeIndex, const SurfacePoints& points,
                    const float* __restrict bary1, const float* __restrict bary2,
                    const float* __restrict r, float* __restrict out) {
    for (size_t i = 0; i < points.n; ++i) {
        const uint32_t* a = &attributeIndex[3 * static_cast<size_t>(points.facet[i])];
        const float b1 = bary1[i], b2 = bary2[i];
        out[i] = (1.0f - b1 - b2) * r[a[0]] + b1 * r[a[1]] + b2 * r[a[2]];
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
                  const float* __restrict bary1, const float* __restrict bary2,
                  const float* __restrict dd, ProbeQuery* queries) {
    const float s = view.footprintScale;
    const uint32_t* const attributeIndex = mesh.attributeIndex.data();
    for (size_t i = 0; i < points.n; ++i) {
        const uint32_t* a = &attributeIndex[3 * static_cast<size_t>(points.facet[i])];
        const ChartPoint& c0 = mesh.attributeChartPoint[a[0]];
        const ChartPoint& c1 = mesh.attributeChartPoint[a[1]];
        const ChartPoint& c2 = mesh.attributeChartPoint[a[2]];
        const float du1 = c1.u - c0.u, du2 = c2.u - c0.u, dv1 = c1.v - c0.v, dv2 = c2.v - c0.v;
        const float b1 = bary1[i], b2 = bary2[i];
        const float* d = dd + 4 * i;
        ProbeQuery& q = queries[i];
        q.chart = c0.chart;
        q.u = c0.u + b1 * du1 + b2 * du2;
        q.v = c0.v + b1 * dv1 + b2 * dv2;
        q.dudx = s * (du1 * d[0] + du2 * d[2]);
        q.dudy = s * (du1 * d[1] + du2 * d[3]);
        q.dvdx = s * (dv1 * d[0] + dv2 * d[2]);
        q.dvdy = s * (dv1 * d[1] + dv2 * d[3]);
    }
}

// Step 5: the static n-tuple probed from the map into the batch's channels; the tiles the
// probes found missing added to scratch.missing, sorted and without repeats. Returns how many
// probes found a tile missing when stopping at missing ones (those points marked in `missed`).
size_t probeChannels(const ShaderMap& map, const ProbeOptions& probe, bool stopAtMissing, size_t n,
                     size_t channels, uint8_t* missed, SurfaceShadingScratch& scratch,
                     SurfaceShadingCounters& counters) {
    scratch.probed.resize(n * channels);
    scratch.reported.resize(8192);
    ProbeResidency residency;
    residency.missing = scratch.reported.data();
    residency.capacity = scratch.reported.size();
    residency.stopAtMissing = stopAtMissing;
    residency.queryMissed = stopAtMissing ? missed : nullptr;
    probeShaderMap(map, probe, {scratch.queries.data(), n}, scratch.probed.data(), &residency);
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
    ShadingBatch& batch = scratch.batch;
    for (size_t c = 0; c < channels; ++c) {
        float* dst = batch.channel(c);
        for (size_t i = 0; i < n; ++i) dst[i] = scratch.probed[i * channels + c];
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
    // sanitizeShade (compositing.h) without a branch, so the loop vectorizes: x - x is 0
    // for a finite x and NaN otherwise, and a sum with a NaN is not 0.
    const float *c0 = batch.out.Ci[0], *c1 = batch.out.Ci[1], *c2 = batch.out.Ci[2];
    const float *o0 = batch.out.Oi[0], *o1 = batch.out.Oi[1], *o2 = batch.out.Oi[2];
    uint64_t nonFinite = 0;
    for (size_t i = 0; i < n; ++i) {
        const float check = (c0[i] - c0[i]) + (c1[i] - c1[i]) + (c2[i] - c2[i]) + (o0[i] - o0[i]) +
                            (o1[i] - o1[i]) + (o2[i] - o2[i]);
        const bool finite = check == 0.0f;
        nonFinite += finite ? 0 : 1;
        color[3 * i] = finite ? c0[i] : 0.0f;
        color[3 * i + 1] = finite ? c1[i] : 0.0f;
        color[3 * i + 2] = finite ? c2[i] : 0.0f;
        opacity[3 * i] = finite ? std::clamp(o0[i], 0.0f, 1.0f) : 1.0f;
        opacity[3 * i + 1] = finite ? std::clamp(o1[i], 0.0f, 1.0f) : 1.0f;
        opacity[3 * i + 2] = finite ? std::clamp(o2[i], 0.0f, 1.0f) : 1.0f;
    }
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
    if (useMap) scratch.queries.resize(n);
    float* rows[ShadingBatch::kInputRows];
    for (int r = 0; r < ShadingBatch::kInputRows; ++r) rows[r] = batch.row(r);
    scratch.b1.resize(n), scratch.b2.resize(n);
    if (useMap) scratch.derivatives.resize(4 * n);
    const float* bary1 = scratch.b1.data();
    const float* bary2 = scratch.b2.data();
    const float* px = rows[ShadingBatch::P];
    const float* py = rows[ShadingBatch::P + 1];
    const float* pz = rows[ShadingBatch::P + 2];

    intersectFacets(view, mesh, points, scratch.b1.data(), scratch.b2.data(), rows[ShadingBatch::P],
                    rows[ShadingBatch::P + 1], rows[ShadingBatch::P + 2],
                    useMap ? scratch.derivatives.data() : nullptr);
    viewDirections(view, points, px, py, pz, rows[ShadingBatch::I], rows[ShadingBatch::I + 1],
                   rows[ShadingBatch::I + 2]);
    const uint32_t* const attributeIndex = mesh.attributeIndex.data();
    for (int row : rep.geometryRows)
        interpolateRow(attributeIndex, points, bary1, bary2,
                       attr.rows[static_cast<size_t>(row)].data(),
                       rows[row < VertexAttributes::U ? row : row + 3]);
    if (!attr.rows[VertexAttributes::Nx].empty())
        normalizeRows(n, rows[ShadingBatch::N], rows[ShadingBatch::N + 1],
                      rows[ShadingBatch::N + 2]);
    if (useMap) {
        chartQueries(view, mesh, points, bary1, bary2, scratch.derivatives.data(),
                     scratch.queries.data());
    } else {
        for (size_t c = 0; c < channels; ++c)
            interpolateRow(attributeIndex, points, bary1, bary2,
                           attr.rows[VertexAttributes::kGeometryRows + c].data(), batch.channel(c));
    }
    if (stopAtMissing && missed) std::fill(missed, missed + n, uint8_t{0});
    const auto interpolated = std::chrono::steady_clock::now();
    counters.interpolateSeconds += std::chrono::duration<double>(interpolated - began).count();
    size_t missedCount = 0;
    if (useMap && channels > 0) {
        missedCount =
            probeChannels(*rep.map, probe, stopAtMissing, n, channels, missed, scratch, counters);
        counters.probeSeconds += secondsSince(interpolated);
    }

    runDynamicShader(view, batch.in, n, color, opacity, scratch, counters);
    if (missedCount > 0) {
        missedCount = 0;
        for (size_t i = 0; i < n; ++i) missedCount += missed[i];
    }
    return missedCount;
}

}  // namespace mpshade
