// probe_batch.h -- a batch of probes (probe.h) for one way of reading texels (prober.h):
// footprints, Feline's setup kept across queries with one footprint, the filters, and the
// choice of a build by the map's channel count. Internal linkage, as prober.h explains.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <span>

#include "shadermaps/feline_lanes.h"
#include "shadermaps/prober.h"

namespace mpshade {
// NOLINTNEXTLINE(cert-dcl59-cpp,google-build-namespaces): internal linkage on purpose (prober.h)
namespace {

// The footprint's axes in level-0 texels of the chart's axes (resU0 along u, resV0 along v:
// chart_aspect.h), major first.
struct Footprint {
    float ax, ay, bx, by;  // major and minor axis vectors (texels)
    float major, minor;
};

Footprint footprintOf(const ProbeQuery& q, float resU0, float resV0, float maxAnisotropy,
                      AnisotropyCap cap, float levelAnisotropy) {
    float d[4] = {q.dudx, q.dvdx, q.dudy, q.dvdy};
    bool finite = true;
    for (int i = 0; i < 4; ++i) {
        finite = finite && std::isfinite(d[i]);
        d[i] *= (i & 1) ? resV0 : resU0;
    }
    Footprint f;
    if (!finite) {
        // The widest footprint: everything.
        f.ax = f.bx = f.ay = f.by = 0.0f;
        f.ax = f.by = 1e30f;
        f.major = f.minor = 1e30f;
        return f;
    }
    // Each axis within 1e18 texels: their squares stay finite.
    for (float& x : d) x = std::clamp(x, -1e18f, 1e18f);
    float la = std::sqrt(d[0] * d[0] + d[1] * d[1]), lb = std::sqrt(d[2] * d[2] + d[3] * d[3]);
    f.ax = d[0], f.ay = d[1], f.bx = d[2], f.by = d[3];
    if (lb > la) {
        std::swap(f.ax, f.bx);
        std::swap(f.ay, f.by);
        std::swap(la, lb);
    }
    f.major = la;
    f.minor = lb;
    if (cap == AnisotropyCap::ShrinkMajor && levelAnisotropy > 0.0f && f.minor > 0.0f &&
        f.minor * levelAnisotropy < f.major) {
        const float widen = f.major / (levelAnisotropy * f.minor);
        f.bx *= widen, f.by *= widen;
        f.minor = f.major / levelAnisotropy;
    }
    if (cap == AnisotropyCap::ShrinkMajor && f.minor > 0.0f && f.minor * maxAnisotropy < f.major) {
        const float shrink = f.minor * maxAnisotropy / f.major;
        f.ax *= shrink, f.ay *= shrink;
        f.major = f.minor * maxAnisotropy;
        return f;
    }
    // Cap the eccentricity by widening the minor axis (also for ShrinkMajor when the minor
    // axis is zero: there is no level to keep).
    if (f.minor * maxAnisotropy < f.major) {
        const float widen = f.major / (maxAnisotropy * std::max(f.minor, 1e-30f));
        if (f.minor > 0.0f) {
            f.bx *= widen, f.by *= widen;
        } else {
            // Perpendicular to the major axis.
            const float len = f.major / maxAnisotropy;
            f.bx = -f.ay / std::max(f.major, 1e-30f) * len;
            f.by = f.ax / std::max(f.major, 1e-30f) * len;
        }
        f.minor = f.major / maxAnisotropy;
    }
    return f;
}

// r[i] = lane i of a, b, c, d.
inline void transpose4(Float4 a, Float4 b, Float4 c, Float4 d, Float4* r) {
    const Float4 ab0 = __builtin_shufflevector(a, b, 0, 4, 1, 5);
    const Float4 ab1 = __builtin_shufflevector(a, b, 2, 6, 3, 7);
    const Float4 cd0 = __builtin_shufflevector(c, d, 0, 4, 1, 5);
    const Float4 cd1 = __builtin_shufflevector(c, d, 2, 6, 3, 7);
    r[0] = __builtin_shufflevector(ab0, cd0, 0, 1, 4, 5);
    r[1] = __builtin_shufflevector(ab0, cd0, 2, 3, 6, 7);
    r[2] = __builtin_shufflevector(ab1, cd1, 0, 1, 4, 5);
    r[3] = __builtin_shufflevector(ab1, cd1, 2, 3, 6, 7);
}

template <int C, typename Texels>
void probeAll(const ShaderMap& map, const ProbeOptions& options,
              std::span<const ProbeQuery> queries, ProbeOutput out, ProbeResidency* residency) {
    const int channels = C > 0 ? C : std::min(map.channels(), kMaxChannels);
    const Prober<C, Texels> p(map, residency, channels, map.levels() - 1);
    FelineSetup setup;  // the last one, for the queries after it with the same footprint
    auto one = [&](ProbeQuery q, float* o) {
        if (!std::isfinite(q.u)) q.u = 0.0f;
        if (!std::isfinite(q.v)) q.v = 0.0f;
        // Footprints within 1/16 of each other (the level moves by under 0.09, the line
        // by under 1/16 of its length) share a setup. Against 1/64: shading 1-8% faster on
        // the four examples at 640x360 (per sample and per pixel), PSNR against the
        // reference renderer within 0.02 dB either way (docs/shader-maps.md). The four
        // differences are compared at once: |d| <= tolerance is -tolerance <= d <= tolerance,
        // false for a NaN either way.
        const bool sameFeline = options.filter == ProbeFilter::Feline && sharesSetup(setup, q);
        const float resU0 = p.resU(q.chart, 0), resV0 = p.resV(q.chart, 0);
        const Footprint f = sameFeline ? Footprint{}
                                       : footprintOf(q, resU0, resV0,
                                                     options.filter == ProbeFilter::Trilinear
                                                         ? 1e30f
                                                         : options.maxAnisotropy,
                                                     options.cap, options.levelAnisotropy);
        if (options.filter == ProbeFilter::Trilinear) {
            p.trilinear(q.chart, std::log2(std::max(f.major, 1e-30f)), q.u, q.v, o);
            return;
        }
        if (!sameFeline && !(f.major < 1e20f)) {
            p.bilinear(q.chart, p.maxLevel, q.u, q.v, o);
            return;
        }
        if (options.filter == ProbeFilter::EWA) {
            if (!(f.minor > 0.0f)) {
                p.bilinear(q.chart, 0, q.u, q.v, o);
                return;
            }
            const float lod = std::clamp(std::log2(f.minor), 0.0f, static_cast<float>(p.maxLevel));
            const int l0 = static_cast<int>(lod);
            float a[Prober<C, Texels>::kArr], b[Prober<C, Texels>::kArr];
            p.ewaLevel(q.chart, l0, q.u, q.v, f.ax, f.ay, f.bx, f.by, a);
            if (l0 < p.maxLevel && lod > static_cast<float>(l0)) {
                p.ewaLevel(q.chart, l0 + 1, q.u, q.v, f.ax, f.ay, f.bx, f.by, b);
                const float t = lod - static_cast<float>(l0);
                for (int c = 0; c < channels; ++c) o[c] = a[c] + t * (b[c] - a[c]);
            } else {
                std::copy(a, a + channels, o);
            }
            return;
        }
        // Feline. Its setup depends on the footprint only: neighbouring queries (the
        // samples of a pixel on one facet) mostly share it, so it is kept from the last.
        if (!sameFeline) {
            setup.chart = q.chart;
            setup.derivatives = queryDerivatives(q);
            setup.tolerance = (1.0f / 16.0f) * std::max({std::fabs(q.dudx), std::fabs(q.dvdx),
                                                         std::fabs(q.dudy), std::fabs(q.dvdy)});
            const float minor = std::max(f.minor, 1e-30f);
            const float ratio = std::min(f.major / minor, options.maxAnisotropy);
            setup.n = options.tapsPerRatio >= 2.0f
                          ? std::clamp(static_cast<int>(2.0f * ratio - 0.5f), 1, kMaxTaps)
                          : std::clamp(static_cast<int>(options.tapsPerRatio * ratio + 0.5f), 1,
                                       kMaxTaps);
            const float lod = std::clamp(fastLog2(minor), 0.0f, static_cast<float>(p.maxLevel));
            setup.l0 = static_cast<int>(lod);
            setup.l1 = std::min(setup.l0 + 1, p.maxLevel);
            setup.blend = setup.l1 > setup.l0
                              ? narrowBlend(lod - static_cast<float>(setup.l0), options.levelBlend)
                              : 0.0f;
            // Probe i, d = -half + i step texels from the centre, weighs exp(-2 (d / major)^2).
            const int n = setup.n;
            // Several taps only along a real major axis (n > 1 means major > minor > 0).
            const float half = n > 1 ? f.major - minor : 0.0f;
            const float step = n > 1 ? 2.0f * half / static_cast<float>(n - 1) : 0.0f;
            const float dirU = n > 1 ? f.ax / (f.major * resU0) : 0.0f;
            const float dirV = n > 1 ? f.ay / (f.major * resV0) : 0.0f;
            setup.offsetU = -half * dirU, setup.offsetV = -half * dirV;
            setup.du = step * dirU, setup.dv = step * dirV;
            const float gk = -2.0f / (f.major * f.major);
            float total = 0.0f;
            for (int i = 0; i < n; ++i) {
                const float d = -half + static_cast<float>(i) * step;
                setup.weights[i] = n > 1 ? fastExp(gk * d * d) : 1.0f;
                total += setup.weights[i];
            }
            for (int i = 0; i < n; ++i) setup.weights[i] /= total;
        }
        float sum[Prober<C, Texels>::kArr] = {};
        const float u0 = q.u + setup.offsetU, v0 = q.v + setup.offsetV;
        if (setup.blend < 1.0f)
            p.lineAccumulate(q.chart, setup.l0, u0, v0, setup.du, setup.dv, setup.n, setup.weights,
                             1.0f - setup.blend, sum);
        if (setup.blend > 0.0f)
            p.lineAccumulate(q.chart, setup.l1, u0, v0, setup.du, setup.dv, setup.n, setup.weights,
                             setup.blend, sum);
        for (int c = 0; c < channels; ++c) o[c] = sum[c];
    };
    uint8_t* queryMissed = residency ? residency->queryMissed : nullptr;
    auto write = [&](size_t k, const float* value) {
        if (out.rows) {
            for (int c = 0; c < channels; ++c) out.rows[c][k] = value[c];
        } else {
            float* o = out.interleaved + k * static_cast<size_t>(channels);
            for (int c = 0; c < channels; ++c) o[c] = value[c];
        }
    };
    constexpr int kVectors = Prober<C, Texels>::kVectors;
    const bool lanes = kVectors > 0 && options.filter == ProbeFilter::Feline && p.fast;
    // After lanes that probed nothing the next tries wait 1, 2, 4, then kLanes queries: where
    // tiles are missing (a first pass) every try would fail.
    size_t retry = 0, wait = 1;
    for (size_t k = 0; k < queries.size();) {
        // Up to kLanes at once where they share the setup (feline_lanes.h); else one, which
        // makes the setup the next ones may share.
        if constexpr (kVectors > 0) {
            Float4 block[kLanes][kVectors > 0 ? kVectors : 1];
            const int m =
                lanes && k >= retry
                    ? felineLanes(p, setup, queries.data() + k,
                                  static_cast<int>(std::min<size_t>(kLanes, queries.size() - k)),
                                  block)
                    : 0;
            if (m > 0) {
                int j = 0;
                // Four queries' channels at once into the rows (a 4x4 transpose a vector): the
                // rows then take four stores a channel instead of one a query and channel.
                if (out.rows)
                    for (; j + 4 <= m; j += 4)
                        for (int c = 0; c < kVectors; ++c) {
                            Float4 r[4];
                            transpose4(block[j][c], block[j + 1][c], block[j + 2][c],
                                       block[j + 3][c], r);
                            for (int i = 0; i < 4 && 4 * c + i < channels; ++i)
                                storeFloat4(out.rows[4 * c + i] + k + static_cast<size_t>(j), r[i]);
                        }
                for (; j < m; ++j) {
                    float value[4 * (kVectors > 0 ? kVectors : 1)];
                    for (int c = 0; c < kVectors; ++c) storeFloat4(value + 4 * c, block[j][c]);
                    write(k + static_cast<size_t>(j), value);
                }
                if (queryMissed) std::fill(queryMissed + k, queryMissed + k + m, uint8_t{0});
                k += static_cast<size_t>(m);
                wait = 1;
                continue;
            }
            if (lanes && k >= retry) {
                retry = k + wait;
                wait = std::min<size_t>(2 * wait, kLanes);
            }
        }
        p.missed = false;
        float value[Prober<C, Texels>::kArr];
        one(queries[k], value);
        write(k, value);
        if (queryMissed) queryMissed[k] = p.missed ? 1 : 0;
        ++k;
    }
    if (residency) residency->bilinearProbes += p.fastProbes;
}

// probeShaderMap for Texels, the channel count made a compile-time constant up to 8.
template <typename Texels>
void probeWith(const ShaderMap& map, const ProbeOptions& options,
               std::span<const ProbeQuery> queries, ProbeOutput out, ProbeResidency* residency) {
    switch (map.channels()) {
        case 1:
            return probeAll<1, Texels>(map, options, queries, out, residency);
        case 2:
            return probeAll<2, Texels>(map, options, queries, out, residency);
        case 3:
            return probeAll<3, Texels>(map, options, queries, out, residency);
        case 4:
            return probeAll<4, Texels>(map, options, queries, out, residency);
        case 5:
            return probeAll<5, Texels>(map, options, queries, out, residency);
        case 6:
            return probeAll<6, Texels>(map, options, queries, out, residency);
        case 7:
            return probeAll<7, Texels>(map, options, queries, out, residency);
        case 8:
            return probeAll<8, Texels>(map, options, queries, out, residency);
        default:
            return probeAll<0, Texels>(map, options, queries, out, residency);
    }
}

}  // namespace
}  // namespace mpshade
