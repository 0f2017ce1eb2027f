// prober.h -- the inner loops of shader-map probes (probe.h), for the files that build them
// for one instruction set each: probe.cpp (portable: float, and binary16 converted in
// portable code) and probe_avx2.cpp (AVX2, binary16 by the F16C conversion instructions,
// chosen at run time). Everything here has internal linkage, so each file's copies are compiled
// for its own instruction set and none replaces another's at link time.
//
// Texels, a policy type: Storage (float or uint16_t), kHalf (the map stores binary16),
// load(p) (one channel value) and load4(p) (four consecutive values as a Float4; it may
// read up to four values past p, which TilePool::kSlackBytes keeps inside the block).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iterator>

#include "geometry/float4.h"
#include "shadermaps/half_float.h"
#include "shadermaps/probe.h"
#include "shadermaps/shader_map.h"

namespace mpshade {
// NOLINTNEXTLINE(cert-dcl59-cpp,google-build-namespaces): internal linkage on purpose (above)
namespace {

// Float storage: values are read as they are.
struct FloatTexels {
    using Storage = float;
    static constexpr bool kHalf = false;
    static float load(const float* p) { return *p; }
    static Float4 load4(const float* p) { return loadFloat4(p); }
};

// binary16 storage, converted in portable code: exact (every half is a float), slow.
struct HalfTexels {
    using Storage = uint16_t;
    static constexpr bool kHalf = true;
    static float load(const uint16_t* p) { return halfToFloat(*p); }
    static Float4 load4(const uint16_t* p) {
        return Float4{halfToFloat(p[0]), halfToFloat(p[1]), halfToFloat(p[2]), halfToFloat(p[3])};
    }
};

constexpr int kMaxChannels = 64;
constexpr int kMaxTaps = 63;  // Feline: 2 maxAnisotropy - 1, maxAnisotropy capped at 32

// The weight of the coarser of two levels, t in [0, 1], when they are blended only within
// `width` / 2 of the midpoint between them (width 1: trilinear).
inline float narrowBlend(float t, float width) {
    if (width >= 1.0f) return t;
    if (!(width > 0.0f)) return t < 0.5f ? 0.0f : 1.0f;
    return std::clamp((t - 0.5f) / width + 0.5f, 0.0f, 1.0f);
}

// floor(x) for |x| < 2^31, without a library call (SSE2 has no rounding instruction).
inline float floorOf(float x) {
    const float t = static_cast<float>(static_cast<int32_t>(x));
    return t > x ? t - 1.0f : t;
}

// exp(x) for x <= 0, relative error below 1e-6: 2^(x log2 e) split into an integer power
// (the exponent bits) and 2^f, f in [0, 1), by a degree-5 least-squares polynomial (1.4e-7
// on its own). Feline's weights are normalized, so this is far below anything visible, and
// several times cheaper than std::exp.
inline float fastExp(float x) {
    const float t = std::max(x * 1.44269504f, -126.0f);
    const float fi = floorOf(t);
    const float f = t - fi;
    const float p =
        1.0f + f * (0.6931527f +
                    f * (0.2401532f + f * (0.05582816f + f * (0.008988991f + f * 0.001876627f))));
    int32_t bits;
    std::memcpy(&bits, &p, sizeof bits);
    bits += static_cast<int32_t>(fi) << 23;
    float r;
    std::memcpy(&r, &bits, sizeof r);
    return r;
}

// log2(x) for finite normal x > 0, absolute error below 3e-5: the exponent bits plus
// log2 of the mantissa in [1, 2) by a degree-5 least-squares polynomial. It picks mip
// levels, where 1e-4 of a level is nothing.
inline float fastLog2(float x) {
    int32_t bits;
    std::memcpy(&bits, &x, sizeof bits);
    const float e = static_cast<float>(((bits >> 23) & 0xFF) - 127);
    bits = (bits & 0x007FFFFF) | 0x3F800000;
    float m;
    std::memcpy(&m, &bits, sizeof m);
    const float t = m - 1.0f;
    return e + t * (1.441826f +
                    t * (-0.7086829f + t * (0.4154247f + t * (-0.1944264f + t * 0.04588722f))));
}

// kChannels > 0: the channel count is a compile-time constant, so the per-channel loops
// unroll and vectorize; 0: any count. Texels: how the fast path reads the map's storage
// (FloatTexels, HalfTexels, or a build for an instruction set's conversions).
template <int kChannels, typename Texels>
struct Prober {
    using Storage = typename Texels::Storage;
    const ShaderMap& map;
    ProbeResidency* residency;
    int runtimeChannels;
    int maxLevel;
    static constexpr bool kFixed = kChannels > 0;
    static constexpr int kArr = kFixed ? kChannels : kMaxChannels;
    // The last tile looked up, one per level parity: neighbouring lookups mostly read the
    // same tile, and each lookup otherwise costs a hash-table probe; a tap that falls back
    // reads a level and the next, which with one entry had cost two probes a tap.
    mutable uint64_t lastKey[2] = {~uint64_t{0}, ~uint64_t{0}};
    mutable int lastSlot[2] = {-1, -1};
    // The fast path's own cache, one tile per level parity: trilinear and Feline alternate
    // between two adjacent levels.
    mutable uint64_t cachedKey[2] = {~uint64_t{0}, ~uint64_t{0}};
    mutable int cachedSlot[2] = {-1, -1};
    mutable const Storage* cachedTile[2] = {nullptr, nullptr};  // cachedSlot's storage
    mutable uint64_t fastProbes = 0;  // bilinear probes on the fast path, for residency
    mutable bool missed = false;      // the current query found a tile missing
    // The fast path's constants: texels and tiles along an axis kLevelSlots levels down from
    // level 0, so that an axis shifted by its chart (chart_aspect.h) reads entry level + shift;
    // the tile's geometry; storage as Texels reads it, with no recency to report.
    static constexpr int kLevelSlots = 32 + kMaxChartShift;
    float levelRes[kLevelSlots] = {};
    int levelTiles[kLevelSlots] = {};
    int tileShift = 0, border = 1;
    size_t rowValues = 0;  // channel values per tile row, borders included
    size_t tileBytes = 0;
    // lineInTile's tile per level parity: a tap whose 2x2 texels lie in the tile's storage,
    // borders included, reads it, even where its texel belongs to the next tile: a line that
    // crosses a tile's edge, and the query after it, no longer look the next tile up and
    // then this one again. level -1: none.
    struct TileWindow {
        int chart = -1, level = -1, ox = 0, oy = 0;
        const Storage* t = nullptr;
    };
    mutable TileWindow window[2];
    // Tiles prefetched lately, by slot (direct-mapped).
    static constexpr unsigned kPrefetchMemory = 256;
    mutable int prefetched[kPrefetchMemory];
    // Missing tiles reported lately (direct-mapped by key).
    static constexpr int kReportedBits = 7;
    mutable uint64_t reported[1 << kReportedBits];
    bool fast = false;

    Prober(const ShaderMap& m, ProbeResidency* r, int channels, int top)
        : map(m), residency(r), runtimeChannels(channels), maxLevel(top) {
        while ((1 << tileShift) < map.options().tileSize) ++tileShift;
        for (int level = 0; level < kLevelSlots; ++level) {
            const int res = level < 31 ? std::max(1, map.options().resolution >> level) : 1;
            levelRes[level] = static_cast<float>(res);
            levelTiles[level] = (res + (1 << tileShift) - 1) >> tileShift;
        }
        border = map.options().border;
        rowValues = static_cast<size_t>(map.stride()) * static_cast<size_t>(runtimeChannels);
        tileBytes = map.tileBytes();
        std::fill(std::begin(prefetched), std::end(prefetched), -1);
        std::fill(std::begin(reported), std::end(reported), ~uint64_t{0});
        fast = map.options().halfPrecision == Texels::kHalf && !(residency && residency->touched);
    }

    // Chart `chart`'s texels along u (resU) and v (resV) at `level` (chart_aspect.h).
    int shiftU(int chart) const { return map.shiftU(static_cast<uint32_t>(chart)); }
    int shiftV(int chart) const { return map.shiftV(static_cast<uint32_t>(chart)); }
    float resU(int chart, int level) const { return levelRes[level + shiftU(chart)]; }
    float resV(int chart, int level) const { return levelRes[level + shiftV(chart)]; }

    // The fast path's tile lookup: the storage of tile (tx, ty) of `level`, or null if it is
    // not resident. Neighbouring lookups mostly find the last tile of their level's parity.
    const Storage* tileAt(int chart, int level, int tx, int ty) const {
        const uint64_t key = (uint64_t(static_cast<uint32_t>(chart)) << 37) |
                             (uint64_t(level) << 32) | (uint64_t(tx) << 16) | uint64_t(ty);
        const int parity = level & 1;
        if (key != cachedKey[parity]) lookUpTile(key, chart, level, tx, ty);
        return cachedTile[parity];
    }

    __attribute__((noinline)) void lookUpTile(uint64_t key, int chart, int level, int tx,
                                              int ty) const {
        const int parity = level & 1;
        cachedKey[parity] = key;
        cachedSlot[parity] = map.slotOf({static_cast<uint32_t>(chart), static_cast<uint16_t>(level),
                                         static_cast<uint16_t>(tx), static_cast<uint16_t>(ty)});
        cachedTile[parity] = nullptr;
        const int slot = cachedSlot[parity];
        if (slot < 0) return;
        map.markUsed(slot);
        cachedTile[parity] = reinterpret_cast<const Storage*>(map.tileStorage(slot));
        // The whole tile, now: a probe's taps walk a line through it and the next rows of
        // points come back to it, while the first load of a tap otherwise waits on memory
        // (a third of the probe's time). 17% off the vase's steady frame, 5-8% off the
        // teapot's and 11% off the courtyard's. Once per tile in a while: rows of points
        // enter the same tiles again.
        int& seen = prefetched[static_cast<unsigned>(slot) % kPrefetchMemory];
        if (seen != slot) {
            seen = slot;
            const char* d = reinterpret_cast<const char*>(cachedTile[parity]);
            for (size_t b = 0; d && b < tileBytes; b += 64) __builtin_prefetch(d + b, 0, 3);
        }
    }

    // Adds w * the bilinear interpolation of tile data `t` (origin texel (ox, oy) of the
    // level, borders included in `t`) at texel coordinates (x, y), already clamped.
    template <bool kInterior = false>
    void accumulate(const Storage* __restrict t, int ox, int oy, float x, float y, float w,
                    float* __restrict sum) const {
        const int channels = kFixed ? kChannels : runtimeChannels;
        const float fx0 = kInterior ? static_cast<float>(static_cast<int32_t>(x)) : floorOf(x);
        const float fy0 = kInterior ? static_cast<float>(static_cast<int32_t>(y)) : floorOf(y);
        const int li = static_cast<int>(fx0) - ox + border,
                  lj = static_cast<int>(fy0) - oy + border;
        const float fx = x - fx0, fy = y - fy0;
        const float w00 = w * (1.0f - fx) * (1.0f - fy), w10 = w * fx * (1.0f - fy);
        const float w01 = w * (1.0f - fx) * fy, w11 = w * fx * fy;
        const Storage* t00 = t + static_cast<size_t>(lj) * rowValues +
                             static_cast<size_t>(li) * static_cast<size_t>(channels);
        const Storage *t10 = t00 + channels, *t01 = t00 + rowValues, *t11 = t01 + channels;
        for (int c = 0; c < channels; ++c)
            sum[c] += w00 * Texels::load(t00 + c) + w10 * Texels::load(t10 + c) +
                      w01 * Texels::load(t01 + c) + w11 * Texels::load(t11 + c);
    }

    // accumulate() for up to 8 channels in 4-float vectors (sumLine chooses it by the type
    // of its running sum): each texel's channels are loaded
    // whole, lanes past the last channel carrying the next texel's values (or the pool's
    // slack after the last tile), which are never stored.
    // kInterior: x and y are known to be >= 0, where the floor is the truncation.
    static constexpr int kVectors = kFixed && kChannels <= 8 ? (kChannels + 3) / 4 : 0;
    template <bool kInterior = false>
    void accumulate(const Storage* __restrict t, int ox, int oy, float x, float y, float w,
                    Float4* acc) const {
        const float fx0 = kInterior ? static_cast<float>(static_cast<int32_t>(x)) : floorOf(x);
        const float fy0 = kInterior ? static_cast<float>(static_cast<int32_t>(y)) : floorOf(y);
        const int li = static_cast<int>(fx0) - ox + border,
                  lj = static_cast<int>(fy0) - oy + border;
        const float fx = x - fx0, fy = y - fy0;
        const float wy0 = w * (1.0f - fy), wy1 = w * fy;
        const float w00 = wy0 * (1.0f - fx), w10 = wy0 * fx, w01 = wy1 * (1.0f - fx),
                    w11 = wy1 * fx;
        addTexels(t + static_cast<size_t>(lj) * rowValues +
                      static_cast<size_t>(li) * static_cast<size_t>(kChannels),
                  w00, w10, w01, w11, acc);
    }

    // Adds the 2x2 texels from t00 (t00's row and the next), weighted, to acc: the sum every
    // vector path of a tap makes (feline_lanes.h too), in one order so they agree bit for bit.
    void addTexels(const Storage* t00, float w00, float w10, float w01, float w11,
                   Float4* acc) const {
        const Storage* t01 = t00 + rowValues;
        for (int k = 0; k < kVectors; ++k)
            acc[k] +=
                w00 * Texels::load4(t00 + 4 * k) + w10 * Texels::load4(t00 + kChannels + 4 * k) +
                w01 * Texels::load4(t01 + 4 * k) + w11 * Texels::load4(t01 + kChannels + 4 * k);
    }

    // The fast path of a bilinear probe: adds w * the bilinear interpolation at texel
    // coordinates (x, y) of `level` (texel centres at integers) to sum, if the tile is
    // resident in float storage; returns false (nothing added) otherwise.
    bool tap(int chart, int level, float x, float y, float w, float* sum) const {
        const int lu = level + shiftU(chart), lv = level + shiftV(chart);
        x = std::clamp(x, -0.5f, levelRes[lu] - 0.5f);
        y = std::clamp(y, -0.5f, levelRes[lv] - 0.5f);
        const int tx =
            std::min(std::max(static_cast<int>(floorOf(x)), 0) >> tileShift, levelTiles[lu] - 1);
        const int ty =
            std::min(std::max(static_cast<int>(floorOf(y)), 0) >> tileShift, levelTiles[lv] - 1);
        const Storage* t = tileAt(chart, level, tx, ty);
        if (!t) return false;
        ++fastProbes;
        accumulate(t, tx << tileShift, ty << tileShift, x, y, w, sum);
        return true;
    }

    int find(uint32_t chart, int level, int i, int j, int& li, int& lj) const {
        const TileKey key = map.tileOf(chart, level, i, j);
        const int T = map.options().tileSize;
        li = i - key.tx * T + border;
        lj = j - key.ty * T + border;
        const uint64_t packed = key.packed();
        const int p = level & 1;
        if (packed != lastKey[p]) {
            lastKey[p] = packed;
            lastSlot[p] = map.slotOf(key);
            if (lastSlot[p] >= 0) map.markUsed(lastSlot[p]);
        }
        return lastSlot[p];
    }

    // Reports a missing tile unless it was reported lately: the taps of a frame's probes
    // that find tiles missing ask for the same few again and again, and each report costs its
    // caller a sort (a camera outrunning its fills had spent 11% of a frame sorting them).
    void report(const TileKey& key) const {
        const uint64_t packed = key.packed();
        uint64_t& last = reported[(packed * 0x9E3779B97F4A7C15ull) >> (64 - kReportedBits)];
        if (last == packed || residency->count >= residency->capacity) return;
        last = packed;
        residency->missing[residency->count++] = key;
    }

    // Bilinear probe of level `level` at chart (u, v), falling back to coarser resident levels.
    void bilinear(int chart, int level, float u, float v, float* out) const {
        const int channels = kFixed ? kChannels : runtimeChannels;
        for (;; ++level) {
            const auto ru =
                static_cast<float>(map.resolutionU(static_cast<uint32_t>(chart), level));
            const auto rv =
                static_cast<float>(map.resolutionV(static_cast<uint32_t>(chart), level));
            const float x = std::clamp(u * ru - 0.5f, -0.5f, ru - 0.5f);
            const float y = std::clamp(v * rv - 0.5f, -0.5f, rv - 0.5f);
            const float fx0 = floorOf(x), fy0 = floorOf(y);
            const int i0 = static_cast<int>(fx0), j0 = static_cast<int>(fy0);
            int li, lj;
            const int slot =
                find(static_cast<uint32_t>(chart), level, std::max(i0, 0), std::max(j0, 0), li, lj);
            li += i0 - std::max(i0, 0);
            lj += j0 - std::max(j0, 0);
            if (residency) ++residency->bilinearProbes;
            if (slot < 0) {
                missed = true;
                if (residency) {
                    ++residency->missingProbes;
                    report(map.tileOf(static_cast<uint32_t>(chart), level, std::max(i0, 0),
                                      std::max(j0, 0)));
                    if (residency->stopAtMissing || level >= maxLevel) {
                        std::fill(out, out + channels, 0.0f);
                        return;
                    }
                    ++residency->fallbacks;
                } else if (level >= maxLevel) {
                    std::fill(out, out + channels, 0.0f);
                    return;
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

    // Feline's taps at one level: adds scale * weight[i] * bilinear(u0 + i du, v0 + i dv) to
    // sum for i < n. The taps walk a straight line, so texel coordinates advance by a
    // constant step and the bilinear weights go straight into the sum. The common case is
    // inlined at the call, the rest (lines near a level's edge or across tiles, missing
    // tiles, half storage, recency to report) is out of line: kept apart, the common case
    // compiles to a third of the instructions (callgrind, the vase's steady frame).
    [[gnu::always_inline]] void lineAccumulate(int chart, int level, float u0, float v0, float du,
                                               float dv, int n, const float* weight, float scale,
                                               float* sum) const {
        if (fast && lineInTile(chart, level, u0, v0, du, dv, n, weight, scale, sum)) return;
        lineAccumulateAnywhere(chart, level, u0, v0, du, dv, n, weight, scale, sum);
    }

    // lineAccumulate's common case: the line inside the level, away from its last texel,
    // so no tap is clamped and each floor is a truncation; each tap reads the tile its
    // texel lies in (a tile's border holds the next texel), the line's taps mostly one,
    // sometimes two. Returns false, having added nothing, if a tile is not resident or
    // the line is not inside.
    [[gnu::always_inline]] bool lineInTile(int chart, int level, float u0, float v0, float du,
                                           float dv, int n, const float* weight, float scale,
                                           float* sum) const {
        const float fu = resU(chart, level), fv = resV(chart, level);
        const float x0 = u0 * fu - 0.5f, y0 = v0 * fv - 0.5f;
        const float dx = du * fu, dy = dv * fv;
        const float xe = x0 + static_cast<float>(n - 1) * dx,
                    ye = y0 + static_cast<float>(n - 1) * dy;
        if (!(std::min(x0, xe) >= 0.0f && std::min(y0, ye) >= 0.0f &&
              std::max(x0, xe) < fu - 1.0f && std::max(y0, ye) < fv - 1.0f))
            return false;
        TileWindow& w = window[level & 1];
        if (w.chart != chart || w.level != level) {
            w.chart = chart, w.level = level;
            w.ox = w.oy = -(1 << 30);  // no tap fits: the first one looks its tile up
        }
        // A tap at texel ix reads ix and ix + 1: both within [ox - border, ox + size +
        // border - 1], the tile's storage.
        const unsigned reach = static_cast<unsigned>((1 << tileShift) + 2 * border - 2);
        const bool whole = sumLine(n, x0, y0, dx, dy, sum, [&](int i, float x, float y, auto* acc) {
            const int ix = static_cast<int>(x), iy = static_cast<int>(y);
            if (static_cast<unsigned>(ix - w.ox + border) > reach ||
                static_cast<unsigned>(iy - w.oy + border) > reach) {
                const int tx = ix >> tileShift, ty = iy >> tileShift;
                w.t = tileAt(chart, level, tx, ty);
                if (!w.t) return false;
                w.ox = tx << tileShift, w.oy = ty << tileShift;
            }
            accumulate<true>(w.t, w.ox, w.oy, x, y, weight[i] * scale, acc);
            return true;
        });
        if (!whole) w.level = -1;
        return whole;
    }

    // Sums a line's n taps, from texel coordinates (x, y) by (dx, dy), into sum:
    // tap(i, x, y, acc) adds tap i to the running sum acc by accumulate(), or returns false
    // to give the line up, sum untouched. Within up to 8 channels the taps sum in vectors
    // from zero, added to sum at the end; otherwise in a copy of sum the compiler can keep
    // in registers.
    template <typename Tap>
    bool sumLine(int n, float x, float y, float dx, float dy, float* sum, Tap&& tap) const {
        const int channels = kFixed ? kChannels : runtimeChannels;
        if constexpr (kVectors > 0) {
            Float4 acc[kVectors] = {};
            for (int i = 0; i < n; ++i, x += dx, y += dy)
                if (!tap(i, x, y, acc)) return false;
            float lanes[4 * (kVectors > 0 ? kVectors : 1)];
            for (int k = 0; k < kVectors; ++k) storeFloat4(lanes + 4 * k, acc[k]);
            for (int c = 0; c < channels; ++c) sum[c] += lanes[c];
        } else {
            float acc[kArr];
            for (int c = 0; c < channels; ++c) acc[c] = sum[c];
            for (int i = 0; i < n; ++i, x += dx, y += dy)
                if (!tap(i, x, y, acc)) return false;
            for (int c = 0; c < channels; ++c) sum[c] = acc[c];
        }
        fastProbes += static_cast<uint64_t>(n);
        return true;
    }

    __attribute__((noinline)) void lineAccumulateAnywhere(int chart, int level, float u0, float v0,
                                                          float du, float dv, int n,
                                                          const float* weight, float scale,
                                                          float* sum) const {
        const int channels = kFixed ? kChannels : runtimeChannels;
        const int lu = level + shiftU(chart), lv = level + shiftV(chart);
        const float fu = levelRes[lu], fv = levelRes[lv];
        const float x0 = u0 * fu - 0.5f, y0 = v0 * fv - 0.5f;
        const float dx = du * fu, dy = dv * fv;
        if (fast) {
            const float xe = x0 + static_cast<float>(n - 1) * dx,
                        ye = y0 + static_cast<float>(n - 1) * dy;
            // Every tap's texels in one tile (the common case: taps span a few texels):
            // one lookup for the line.
            const float lo = -0.5f, hiU = fu - 0.5f, hiV = fv - 0.5f;
            const int ix0 = static_cast<int>(floorOf(std::clamp(std::min(x0, xe), lo, hiU)));
            const int ix1 = static_cast<int>(floorOf(std::clamp(std::max(x0, xe), lo, hiU)));
            const int iy0 = static_cast<int>(floorOf(std::clamp(std::min(y0, ye), lo, hiV)));
            const int iy1 = static_cast<int>(floorOf(std::clamp(std::max(y0, ye), lo, hiV)));
            const int tx = std::min(std::max(ix0, 0) >> tileShift, levelTiles[lu] - 1);
            const int ty = std::min(std::max(iy0, 0) >> tileShift, levelTiles[lv] - 1);
            const int ox = tx << tileShift, oy = ty << tileShift;
            const int size = 1 << tileShift;
            // Texels ix0 .. ix1 + 1 must lie in the tile with its border.
            if (ix0 >= ox - border && ix1 + 1 < ox + size + border && iy0 >= oy - border &&
                iy1 + 1 < oy + size + border) {
                if (const Storage* t = tileAt(chart, level, tx, ty)) {
                    sumLine(n, x0, y0, dx, dy, sum, [&](int i, float x, float y, auto* acc) {
                        accumulate(t, ox, oy, std::clamp(x, lo, hiU), std::clamp(y, lo, hiV),
                                   weight[i] * scale, acc);
                        return true;
                    });
                    return;
                }
                // The whole line finds its tile missing: it falls back as a line, to the next
                // coarser level's fast path, as its taps one by one would (each is the same
                // bilinear probe of that level at the same chart point), for one lookup
                // instead of two a tap -- a frame whose camera outruns its fills had shaded
                // 2.7x slower on its fallbacks (the grazing floor, 640x360).
                if (level < maxLevel && !(residency && residency->stopAtMissing)) {
                    missed = true;
                    if (residency) {
                        const uint64_t taps = static_cast<uint64_t>(n);
                        residency->bilinearProbes += taps;
                        residency->missingProbes += taps;
                        residency->fallbacks += taps;
                        report({static_cast<uint32_t>(chart), static_cast<uint16_t>(level),
                                static_cast<uint16_t>(tx), static_cast<uint16_t>(ty)});
                    }
                    return lineAccumulate(chart, level + 1, u0, v0, du, dv, n, weight, scale, sum);
                }
            }
        }
        float x = x0, y = y0;
        for (int i = 0; i < n; ++i, x += dx, y += dy) {
            const float ws = weight[i] * scale;
            if (fast && tap(chart, level, x, y, ws, sum)) continue;
            // Missing tiles, half storage, or recency to report: the general path.
            float value[kArr];
            bilinear(chart, level, (x + 0.5f) / fu, (y + 0.5f) / fv, value);
            for (int c = 0; c < channels; ++c) sum[c] += ws * value[c];
        }
    }

    void trilinear(int chart, float lod, float u, float v, float* out) const {
        const int channels = kFixed ? kChannels : runtimeChannels;
        if (!(lod > 0.0f)) return bilinear(chart, 0, u, v, out);
        if (lod >= static_cast<float>(maxLevel)) return bilinear(chart, maxLevel, u, v, out);
        const int l0 = static_cast<int>(lod);
        const float t = lod - static_cast<float>(l0);
        // At an exact level the other one weighs nothing: not read, and not asked for.
        if (t == 0.0f) return bilinear(chart, l0, u, v, out);
        if (fast) {
            float sum[kArr] = {};
            if (tap(chart, l0, u * resU(chart, l0) - 0.5f, v * resV(chart, l0) - 0.5f, 1.0f - t,
                    sum) &&
                tap(chart, l0 + 1, u * resU(chart, l0 + 1) - 0.5f, v * resV(chart, l0 + 1) - 0.5f,
                    t, sum)) {
                for (int c = 0; c < channels; ++c) out[c] = sum[c];
                return;
            }
        }
        float a[kArr], b[kArr];
        bilinear(chart, l0, u, v, a);
        bilinear(chart, l0 + 1, u, v, b);
        for (int c = 0; c < channels; ++c) out[c] = a[c] + t * (b[c] - a[c]);
    }

    // One texel of a level for EWA, clamped to the chart; missing tiles fall back.
    void texelAt(int chart, int level, int i, int j, float* out) const {
        const int ru = map.resolutionU(static_cast<uint32_t>(chart), level);
        const int rv = map.resolutionV(static_cast<uint32_t>(chart), level);
        i = std::clamp(i, 0, ru - 1);
        j = std::clamp(j, 0, rv - 1);
        const TileKey key = map.tileOf(static_cast<uint32_t>(chart), level, i, j);
        const int slot = map.slotOf(key);
        if (slot >= 0) {
            map.markUsed(slot);
            return map.texel(key, slot, i, j, out);
        }
        bilinear(chart, level, (i + 0.5f) / ru, (j + 0.5f) / rv, out);
    }

    void ewaLevel(int chart, int level, float u, float v, float ax, float ay, float bx, float by,
                  float* out) const {
        const int channels = kFixed ? kChannels : runtimeChannels;
        // The axes come in level-0 texels of each chart axis.
        const float ru = resU(chart, level), rv = resV(chart, level);
        const float scaleU = ru / resU(chart, 0), scaleV = rv / resV(chart, 0);
        ax *= scaleU, ay *= scaleV, bx *= scaleU, by *= scaleV;
        const float s = u * ru - 0.5f, t = v * rv - 0.5f;
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

}  // namespace
}  // namespace mpshade
