#include "phases/surface_points.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "phases/compositing.h"

namespace mpshade {

size_t shadeSurfacePoints(const ObjectView& view, const ProbeOptions& probe, bool stopAtMissing,
                          const SurfacePoints& points, float* color, float* opacity,
                          uint8_t* missed, SurfaceShadingScratch& scratch,
                          SurfaceShadingCounters& counters) {
    const ObjectRepresentation& rep = *view.rep;
    const FacetMesh& mesh = rep.mesh;
    const VertexAttributes& attr = mesh.attributes;
    const bool useMap = rep.map != nullptr;
    const size_t n = points.n;
    const size_t channels =
        useMap ? static_cast<size_t>(rep.map->channels()) : static_cast<size_t>(mesh.channels);
    ShadingBatch& batch = scratch.batch;
    batch.resize(n, channels);
    if (useMap) scratch.queries.resize(n);
    float* rows[ShadingBatch::kInputRows];
    for (int r = 0; r < ShadingBatch::kInputRows; ++r) rows[r] = batch.row(r);
    const bool readsN = !attr.rows[VertexAttributes::Nx].empty();
    // Per facet (consecutive points mostly share one: the samples of a pixel, the pixels of
    // a facet): its corners and the rearranged triple products.
    size_t facet = ~size_t{0};
    const uint32_t* a = nullptr;
    glm::vec3 P0(0.0f), e1(0.0f), e2(0.0f), A1(0.0f), A2(0.0f), Dn(0.0f);
    float dxA1 = 0.0f, dyA1 = 0.0f, dxA2 = 0.0f, dyA2 = 0.0f, dxDn = 0.0f, dyDn = 0.0f;
    for (size_t i = 0; i < n; ++i) {
        if (points.facet[i] != facet) {
            facet = points.facet[i];
            const uint32_t* p = &mesh.positionIndex[3 * facet];
            a = &mesh.attributeIndex[3 * facet];
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
        const float b0 = 1.0f - b1 - b2;
        const glm::vec3 P = P0 + b1 * e1 + b2 * e2;
        rows[ShadingBatch::P][i] = P.x;
        rows[ShadingBatch::P + 1][i] = P.y;
        rows[ShadingBatch::P + 2][i] = P.z;
        const glm::vec3 toP = P - view.eye;
        const float len = glm::length(toP);
        // One division, not three (divisions dominated this loop's profile).
        const glm::vec3 I = len > 0.0f ? toP * (1.0f / len) : glm::normalize(d);
        rows[ShadingBatch::I][i] = I.x;
        rows[ShadingBatch::I + 1][i] = I.y;
        rows[ShadingBatch::I + 2][i] = I.z;
        for (int row : rep.geometryRows) {
            const std::vector<float>& r = attr.rows[static_cast<size_t>(row)];
            rows[row < VertexAttributes::U ? row : row + 3][i] =
                b0 * r[a[0]] + b1 * r[a[1]] + b2 * r[a[2]];
        }
        if (readsN) {
            float* nx = rows[ShadingBatch::N];
            float* ny = rows[ShadingBatch::N + 1];
            float* nz = rows[ShadingBatch::N + 2];
            const float l = std::sqrt(nx[i] * nx[i] + ny[i] * ny[i] + nz[i] * nz[i]);
            if (l > 0.0f) {
                const float inv = 1.0f / l;
                nx[i] *= inv, ny[i] *= inv, nz[i] *= inv;
            }
        }
        if (useMap) {
            const ChartPoint& c0 = mesh.attributeChartPoint[a[0]];
            const ChartPoint& c1 = mesh.attributeChartPoint[a[1]];
            const ChartPoint& c2 = mesh.attributeChartPoint[a[2]];
            const float du1 = c1.u - c0.u, du2 = c2.u - c0.u, dv1 = c1.v - c0.v, dv2 = c2.v - c0.v;
            ProbeQuery& q = scratch.queries[i];
            q.chart = c0.chart;
            q.u = c0.u + b1 * du1 + b2 * du2;
            q.v = c0.v + b1 * dv1 + b2 * dv2;
            const float s = view.footprintScale;
            q.dudx = s * (du1 * db1dx + du2 * db2dx);
            q.dudy = s * (du1 * db1dy + du2 * db2dy);
            q.dvdx = s * (dv1 * db1dx + dv2 * db2dx);
            q.dvdy = s * (dv1 * db1dy + dv2 * db2dy);
        } else {
            for (size_t c = 0; c < channels; ++c) {
                const std::vector<float>& r = attr.rows[VertexAttributes::kGeometryRows + c];
                batch.channel(c)[i] = b0 * r[a[0]] + b1 * r[a[1]] + b2 * r[a[2]];
            }
        }
    }
    size_t missedCount = 0;
    if (stopAtMissing && missed) std::fill(missed, missed + n, uint8_t{0});
    if (useMap && channels > 0) {
        scratch.probed.resize(n * channels);
        scratch.lacking.resize(8192);
        ProbeResidency residency;
        residency.missing = scratch.lacking.data();
        residency.capacity = scratch.lacking.size();
        residency.stopAtMissing = stopAtMissing;
        residency.queryMissed = stopAtMissing ? missed : nullptr;
        probeShaderMap(*rep.map, probe, {scratch.queries.data(), n}, scratch.probed.data(),
                       &residency);
        counters.probes += residency.bilinearProbes;
        counters.fallbacks += residency.fallbacks;
        counters.missingProbes += residency.missingProbes;
        if (residency.count > 0) {
            auto packedLess = [](const TileKey& x, const TileKey& y) {
                return x.packed() < y.packed();
            };
            const auto first = scratch.lacking.begin();
            const auto last = first + static_cast<std::ptrdiff_t>(residency.count);
            std::sort(first, last, packedLess);
            const auto end = std::unique(first, last);
            for (auto it = first; it != end; ++it)
                if (scratch.missing.empty() || !(scratch.missing.back() == *it))
                    scratch.missing.push_back(*it);
        }
        if (stopAtMissing && residency.missingProbes > 0) missedCount = residency.missingProbes;
        for (size_t c = 0; c < channels; ++c) {
            float* dst = batch.channel(c);
            for (size_t i = 0; i < n; ++i) dst[i] = scratch.probed[i * channels + c];
        }
    }
    ShadingCounters shading;
    rep.dynamicKernel->run(*view.uniforms, batch.in, n, batch.out, scratch.workspace, shading);
    counters.instructions += shading.instructions;
    for (size_t i = 0; i < n; ++i) {
        float ci[3], oi[3];
        for (int k = 0; k < 3; ++k) ci[k] = batch.out.Ci[k][i], oi[k] = batch.out.Oi[k][i];
        if (!sanitizeShade(ci, oi)) ++counters.nonFinite;
        for (int k = 0; k < 3; ++k) color[3 * i + k] = ci[k], opacity[3 * i + k] = oi[k];
    }
    if (missedCount > 0) {
        missedCount = 0;
        for (size_t i = 0; i < n; ++i) missedCount += missed[i];
    }
    return missedCount;
}

}  // namespace mpshade
