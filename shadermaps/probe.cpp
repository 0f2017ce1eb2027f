#include "shadermaps/probe.h"

#include "shadermaps/half_float.h"

#include <algorithm>
#include <cmath>

namespace mpshade {
namespace {

constexpr int kMaxChannels = 64;

// kChannels > 0: the channel count is a compile-time constant, so the per-channel loops
// unroll and vectorize; 0: any count.
template <int kChannels>
struct Prober {
    const ShaderMap& map;
    ProbeResidency* residency;
    int runtimeChannels;
    int maxLevel;
    static constexpr bool kFixed = kChannels > 0;
    static constexpr int kArr = kFixed ? kChannels : kMaxChannels;

    // Bilinear probe of level `level` at chart (u, v), falling back to coarser resident levels.
    void bilinear(int chart, int level, float u, float v, float* out) const {
        const int channels = kFixed ? kChannels : runtimeChannels;
        for (;; ++level) {
            const int res = map.resolution(level);
            const float x = std::clamp(u * res - 0.5f, -0.5f, res - 0.5f);
            const float y = std::clamp(v * res - 0.5f, -0.5f, res - 0.5f);
            const float fx0 = std::floor(x), fy0 = std::floor(y);
            const int i0 = static_cast<int>(fx0), j0 = static_cast<int>(fy0);
            int li, lj;
            const int slot = map.locate(static_cast<uint32_t>(chart), level, std::max(i0, 0),
                                        std::max(j0, 0), li, lj);
            li += i0 - std::max(i0, 0);
            lj += j0 - std::max(j0, 0);
            if (residency) ++residency->bilinearProbes;
            if (slot < 0 && level < maxLevel) {
                if (residency) {
                    ++residency->fallbacks;
                    if (residency->count < residency->capacity)
                        residency->missing[residency->count++] = map.tileOf(
                            static_cast<uint32_t>(chart), level, std::max(i0, 0), std::max(j0, 0));
                }
                continue;
            }
            if (residency && residency->touched) {
                const TileKey key = map.tileOf(static_cast<uint32_t>(chart), level, std::max(i0, 0),
                                               std::max(j0, 0));
                if (residency->touchedCount == 0 ||
                    !(residency->touched[residency->touchedCount - 1] == key)) {
                    if (residency->touchedCount < residency->touchedCapacity)
                        residency->touched[residency->touchedCount++] = key;
                }
            }
            const float fx = x - fx0, fy = y - fy0;
            const size_t row = static_cast<size_t>(map.stride()) * static_cast<size_t>(channels);
            const size_t at = (static_cast<size_t>(lj) * static_cast<size_t>(map.stride()) +
                               static_cast<size_t>(li)) *
                              static_cast<size_t>(channels);
            if (const float* t = map.tileFloats(slot)) {
                const float *t00 = t + at, *t10 = t00 + channels, *t01 = t00 + row,
                            *t11 = t01 + channels;
                for (int c = 0; c < channels; ++c) {
                    const float a = t00[c] + fx * (t10[c] - t00[c]);
                    const float b = t01[c] + fx * (t11[c] - t01[c]);
                    out[c] = a + fy * (b - a);
                }
            } else {
                const uint16_t* h = map.tileHalves(slot);
                const uint16_t *t00 = h + at, *t10 = t00 + channels, *t01 = t00 + row,
                               *t11 = t01 + channels;
                for (int c = 0; c < channels; ++c) {
                    const float a00 = halfToFloat(t00[c]), a10 = halfToFloat(t10[c]);
                    const float a01 = halfToFloat(t01[c]), a11 = halfToFloat(t11[c]);
                    const float a = a00 + fx * (a10 - a00);
                    const float b = a01 + fx * (a11 - a01);
                    out[c] = a + fy * (b - a);
                }
            }
            return;
        }
    }

    // Feline's taps at one level: adds scale * w_i * bilinear(u0 + i du, v0 + i dv) to sum
    // for i < n, with w_i from the recurrence w_{i+1} = w_i ratio_i, ratio_{i+1} = ratio_i
    // ratioStep. The taps walk a straight line, so texel coordinates advance by a constant
    // step and the bilinear weights go straight into the sum.
    void lineAccumulate(int chart, int level, float u0, float v0, float du, float dv, int n,
                        float w, float ratioW, float ratioStep, float scale, float* sum) const {
        const int channels = kFixed ? kChannels : runtimeChannels;
        const int res = map.resolution(level);
        const float fres = static_cast<float>(res);
        float x = u0 * fres - 0.5f, y = v0 * fres - 0.5f;
        const float dx = du * fres, dy = dv * fres;
        const size_t stride = static_cast<size_t>(map.stride());
        const size_t row = stride * static_cast<size_t>(channels);
        for (int i = 0; i < n; ++i, x += dx, y += dy, w *= ratioW, ratioW *= ratioStep) {
            const float cx = std::clamp(x, -0.5f, fres - 0.5f),
                        cy = std::clamp(y, -0.5f, fres - 0.5f);
            const float fx0 = std::floor(cx), fy0 = std::floor(cy);
            const int i0 = static_cast<int>(fx0), j0 = static_cast<int>(fy0);
            int li, lj;
            const int slot = map.locate(static_cast<uint32_t>(chart), level, std::max(i0, 0),
                                        std::max(j0, 0), li, lj);
            const float* t = slot >= 0 ? map.tileFloats(slot) : nullptr;
            const float ws = w * scale;
            if (!t || residency) {
                // Missing tiles, half storage, or residency to report: the general path.
                float value[kArr];
                bilinear(chart, level, (x + 0.5f) / fres, (y + 0.5f) / fres, value);
                for (int c = 0; c < channels; ++c) sum[c] += ws * value[c];
                continue;
            }
            li += i0 - std::max(i0, 0);
            lj += j0 - std::max(j0, 0);
            const float fx = cx - fx0, fy = cy - fy0;
            const float w00 = ws * (1.0f - fx) * (1.0f - fy), w10 = ws * fx * (1.0f - fy);
            const float w01 = ws * (1.0f - fx) * fy, w11 = ws * fx * fy;
            const float* t00 = t + (static_cast<size_t>(lj) * stride + static_cast<size_t>(li)) *
                                       static_cast<size_t>(channels);
            const float *t10 = t00 + channels, *t01 = t00 + row, *t11 = t01 + channels;
            for (int c = 0; c < channels; ++c)
                sum[c] += w00 * t00[c] + w10 * t10[c] + w01 * t01[c] + w11 * t11[c];
        }
    }

    void trilinear(int chart, float lod, float u, float v, float* out) const {
        const int channels = kFixed ? kChannels : runtimeChannels;
        if (!(lod > 0.0f)) return bilinear(chart, 0, u, v, out);
        if (lod >= static_cast<float>(maxLevel)) return bilinear(chart, maxLevel, u, v, out);
        const int l0 = static_cast<int>(lod);
        const float t = lod - static_cast<float>(l0);
        float a[kArr], b[kArr];
        bilinear(chart, l0, u, v, a);
        bilinear(chart, l0 + 1, u, v, b);
        for (int c = 0; c < channels; ++c) out[c] = a[c] + t * (b[c] - a[c]);
    }

    // One texel of a level for EWA, clamped to the chart; missing tiles fall back.
    void texelAt(int chart, int level, int i, int j, float* out) const {
        const int res = map.resolution(level);
        i = std::clamp(i, 0, res - 1);
        j = std::clamp(j, 0, res - 1);
        const TileKey key = map.tileOf(static_cast<uint32_t>(chart), level, i, j);
        const int slot = map.slotOf(key);
        if (slot >= 0) return map.texel(key, slot, i, j, out);
        bilinear(chart, level, (i + 0.5f) / res, (j + 0.5f) / res, out);
    }

    void ewaLevel(int chart, int level, float u, float v, float ax, float ay, float bx, float by,
                  float* out) const {
        const int channels = kFixed ? kChannels : runtimeChannels;
        const int res = map.resolution(level);
        const float scale = static_cast<float>(res) / static_cast<float>(map.resolution(0));
        ax *= scale, ay *= scale, bx *= scale, by *= scale;
        const float s = u * res - 0.5f, t = v * res - 0.5f;
        // The implicit ellipse A s^2 + B s t + C t^2 = 1, widened by one texel.
        float A = ay * ay + by * by + 1.0f, B = -2.0f * (ax * ay + bx * by),
              C = ax * ax + bx * bx + 1.0f;
        const float invF = 1.0f / (A * C - 0.25f * B * B);
        A *= invF, B *= invF, C *= invF;
        const float det = -B * B + 4.0f * A * C, invDet = 1.0f / det;
        const float uSqrt = std::sqrt(det * C), vSqrt = std::sqrt(A * det);
        const int s0 = static_cast<int>(std::ceil(s - 2.0f * invDet * uSqrt));
        const int s1 = static_cast<int>(std::floor(s + 2.0f * invDet * uSqrt));
        const int t0 = static_cast<int>(std::ceil(t - 2.0f * invDet * vSqrt));
        const int t1 = static_cast<int>(std::floor(t + 2.0f * invDet * vSqrt));
        double sum[kArr] = {};
        double weight = 0.0;
        float texel[kArr];
        for (int it = t0; it <= t1; ++it) {
            const float tt = static_cast<float>(it) - t;
            for (int is = s0; is <= s1; ++is) {
                const float ss = static_cast<float>(is) - s;
                const float r2 = A * ss * ss + B * ss * tt + C * tt * tt;
                if (!(r2 < 1.0f)) continue;
                const float w = std::exp(-2.0f * r2);
                texelAt(chart, level, is, it, texel);
                for (int c = 0; c < channels; ++c) sum[c] += w * texel[c];
                weight += w;
            }
        }
        if (weight > 0.0) {
            for (int c = 0; c < channels; ++c) out[c] = static_cast<float>(sum[c] / weight);
        } else {
            bilinear(chart, level, u, v, out);
        }
    }
};

// The footprint's axes in level-0 texels, major first; false if it is degenerate.
struct Footprint {
    float ax, ay, bx, by;  // major and minor axis vectors (texels)
    float major, minor;
};

Footprint footprintOf(const ProbeQuery& q, float resolution, float maxAnisotropy) {
    float d[4] = {q.dudx, q.dvdx, q.dudy, q.dvdy};
    bool finite = true;
    for (float& x : d) {
        finite = finite && std::isfinite(x);
        x *= resolution;
    }
    Footprint f;
    if (!finite) {
        // The widest footprint: everything.
        f.ax = f.bx = f.ay = f.by = 0.0f;
        f.ax = f.by = 1e30f;
        f.major = f.minor = 1e30f;
        return f;
    }
    float la = std::hypot(d[0], d[1]), lb = std::hypot(d[2], d[3]);
    f.ax = d[0], f.ay = d[1], f.bx = d[2], f.by = d[3];
    if (lb > la) {
        std::swap(f.ax, f.bx);
        std::swap(f.ay, f.by);
        std::swap(la, lb);
    }
    f.major = la;
    f.minor = lb;
    // Cap the eccentricity by widening the minor axis.
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

}  // namespace

namespace {

template <int C>
void probeAll(const ShaderMap& map, const ProbeOptions& options,
              std::span<const ProbeQuery> queries, float* out, ProbeResidency* residency) {
    const int channels = C > 0 ? C : std::min(map.channels(), kMaxChannels);
    const Prober<C> p{map, residency, channels, map.levels() - 1};
    const float res0 = static_cast<float>(map.resolution(0));
    for (size_t k = 0; k < queries.size(); ++k) {
        ProbeQuery q = queries[k];
        float* o = out + k * static_cast<size_t>(channels);
        if (!std::isfinite(q.u)) q.u = 0.0f;
        if (!std::isfinite(q.v)) q.v = 0.0f;
        const Footprint f = footprintOf(
            q, res0, options.filter == ProbeFilter::Trilinear ? 1e30f : options.maxAnisotropy);
        if (options.filter == ProbeFilter::Trilinear) {
            p.trilinear(q.chart, std::log2(std::max(f.major, 1e-30f)), q.u, q.v, o);
            continue;
        }
        if (!(f.major < 1e20f)) {
            p.bilinear(q.chart, p.maxLevel, q.u, q.v, o);
            continue;
        }
        if (options.filter == ProbeFilter::EWA) {
            if (!(f.minor > 0.0f)) {
                p.bilinear(q.chart, 0, q.u, q.v, o);
                continue;
            }
            const float lod = std::clamp(std::log2(f.minor), 0.0f, static_cast<float>(p.maxLevel));
            const int l0 = static_cast<int>(lod);
            float a[Prober<C>::kArr], b[Prober<C>::kArr];
            p.ewaLevel(q.chart, l0, q.u, q.v, f.ax, f.ay, f.bx, f.by, a);
            if (l0 < p.maxLevel && lod > static_cast<float>(l0)) {
                p.ewaLevel(q.chart, l0 + 1, q.u, q.v, f.ax, f.ay, f.bx, f.by, b);
                const float t = lod - static_cast<float>(l0);
                for (int c = 0; c < channels; ++c) o[c] = a[c] + t * (b[c] - a[c]);
            } else {
                std::copy(a, a + channels, o);
            }
            continue;
        }
        // Feline.
        const float minor = std::max(f.minor, 1e-30f);
        const float ratio = std::min(f.major / minor, options.maxAnisotropy);
        const int n = std::max(1, static_cast<int>(std::lround(2.0f * ratio - 1.0f)));
        const float lod = std::log2(minor);
        if (n == 1) {
            p.trilinear(q.chart, lod, q.u, q.v, o);
            continue;
        }
        const float half = f.major - minor;
        const float dirU = f.ax / (f.major * res0),
                    dirV = f.ay / (f.major * res0);  // chart units per texel
        // Every probe uses the same two levels; weights exp(-2 (d / major)^2) along an
        // arithmetic progression of d follow a recurrence: two exp() calls per lookup.
        const float clampedLod = std::clamp(lod, 0.0f, static_cast<float>(p.maxLevel));
        const int l0 = static_cast<int>(clampedLod);
        const int l1 = std::min(l0 + 1, p.maxLevel);
        const float blend = l1 > l0 ? clampedLod - static_cast<float>(l0) : 0.0f;
        const float step = 2.0f * half / static_cast<float>(n - 1);
        const float gk = 2.0f / (f.major * f.major);
        float w = std::exp(-gk * half * half);                              // at d = -half
        float ratioW = std::exp(-gk * (step * step - 2.0f * half * step));  // w(d + step) / w(d)
        const float ratioStep = std::exp(-2.0f * gk * step * step);
        float sum[Prober<C>::kArr] = {};
        float weight = 0.0f;
        {
            float wi = w, ri = ratioW;
            for (int i = 0; i < n; ++i, wi *= ri, ri *= ratioStep) weight += wi;
        }
        const float u0 = q.u - half * dirU, v0 = q.v - half * dirV;
        const float du = step * dirU, dv = step * dirV;
        p.lineAccumulate(q.chart, l0, u0, v0, du, dv, n, w, ratioW, ratioStep, 1.0f - blend, sum);
        if (blend > 0.0f)
            p.lineAccumulate(q.chart, l1, u0, v0, du, dv, n, w, ratioW, ratioStep, blend, sum);
        for (int c = 0; c < channels; ++c) o[c] = sum[c] / weight;
    }
}

}  // namespace

void probeShaderMap(const ShaderMap& map, const ProbeOptions& options,
                    std::span<const ProbeQuery> queries, float* out, ProbeResidency* residency) {
    switch (map.channels()) {
        case 1:
            return probeAll<1>(map, options, queries, out, residency);
        case 2:
            return probeAll<2>(map, options, queries, out, residency);
        case 3:
            return probeAll<3>(map, options, queries, out, residency);
        case 4:
            return probeAll<4>(map, options, queries, out, residency);
        case 8:
            return probeAll<8>(map, options, queries, out, residency);
        default:
            return probeAll<0>(map, options, queries, out, residency);
    }
}

}  // namespace mpshade
