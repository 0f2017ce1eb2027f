// probe.h -- filtered lookups of shader maps (patent col. 10, claims 13-14), batched: a
// span of queries in, n-tuples out.
//
//   Trilinear: two bilinear probes of adjacent levels, blended (Williams 1983); one at an
//     exact level, where the other would weigh nothing. The level is log2 of the
//     footprint's longer axis in level-0 texels.
//   Feline (McCormack et al. 1999): trilinear probes along the footprint ellipse's major
//     axis; the minor axis picks the level. n = 2 (major / minor) - 1 probes (the ratio
//     capped by maxAnisotropy, see AnisotropyCap), spread over a line of
//     half length major - minor so the end probes' footprints reach the ellipse's ends,
//     weighted by exp(-2 (d / major)^2) for a probe d texels from the centre.
//   EWA (Heckbert 1989; Greene and Heckbert 1986): the elliptical Gaussian exp(-2 r^2) over
//     every texel inside the ellipse (widened by one texel for reconstruction, as pbrt-v4
//     does), at the two levels around log2(minor), blended. The quality reference.
//
// The footprint is the Jacobian of chart coordinates with respect to screen position:
// (du/dx, dv/dx) and (du/dy, dv/dy). Zero, NaN or infinite derivatives and extreme
// anisotropy still give finite results: non-finite derivatives count as the widest
// footprint (the coarsest level).
//
// Residency: a probe never fills and never allocates. A bilinear probe whose tile is not
// resident uses the finest resident coarser level, records the fallback, and reports the
// tile it found missing into the caller's buffer (while it has room); the tiles it did read go
// to a second buffer, for the tile cache's recency. With `stopAtMissing` (a caller that
// will fill what was missing and probe again, as `render` does) it reports the missing
// tile and looks no further: the result is then meaningless, and no coarser tile is
// reported that the repeated probe would not need.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "shadermaps/shader_map.h"

namespace mpshade {

enum class ProbeFilter { Trilinear, Feline, EWA };

// How a footprint more eccentric than maxAnisotropy is brought within it.
//   WidenMinor: the minor axis grows to major / maxAnisotropy (a coarser level): a lone
//     probe then never aliases, at the price of blur across the major axis (the classic
//     choice, as GPUs and pbrt-v4 make it).
//   ShrinkMajor: the major axis shrinks to minor * maxAnisotropy (the level stays the
//     minor axis's): the probe under-filters along the major axis, which suits a caller
//     that supersamples the screen anyway -- the renderer's samples at 1/sqrt(spp) pixel
//     spacing integrate along it, and widening would blur what they resolve. Measured
//     against 64-sample references in docs/multiphase.md.
enum class AnisotropyCap { WidenMinor, ShrinkMajor };

struct ProbeOptions {
    ProbeFilter filter = ProbeFilter::Feline;
    float maxAnisotropy = 16.0f;  // Feline and EWA: the longest footprint over the shortest
    // Feline: the fraction of each level's span over which two levels are blended (1:
    // trilinear everywhere; less: one level away from the transitions, half the taps).
    float levelBlend = 1.0f;
    // Feline: taps per unit of anisotropy; 2 is McCormack et al.'s 2 ratio - 1 taps, one
    // minor axis apart; fewer spread the same line more thinly.
    float tapsPerRatio = 2.0f;
    AnisotropyCap cap = AnisotropyCap::WidenMinor;
    // ShrinkMajor: the finest level a footprint reads is that of major / levelAnisotropy.
    // A footprint more eccentric than this (a floor near the horizon) first has its minor
    // axis widened to major / levelAnisotropy, then its major axis shortened as ShrinkMajor
    // does; footprints within it are not changed. Without it an oblique footprint reads --
    // and its map fills -- texels as fine as its minor axis over a major axis dozens of
    // times longer. 0: no such bound.
    float levelAnisotropy = 0.0f;
};

struct ProbeQuery {
    int chart = 0;
    float u = 0.0f, v = 0.0f;  // chart coordinates; a little outside [0, 1] reads the border
    float dudx = 0.0f, dvdx = 0.0f, dudy = 0.0f, dvdy = 0.0f;  // per screen pixel
};

struct ProbeResidency {
    TileKey* missing = nullptr;  // caller's buffer for tiles that were missing
    size_t capacity = 0;
    size_t count = 0;        // written to missing (duplicates possible)
    uint64_t fallbacks = 0;  // bilinear probes answered from a coarser level
    uint64_t bilinearProbes = 0;
    TileKey* touched = nullptr;  // caller's buffer for the resident tiles read (for an LRU)
    size_t touchedCapacity = 0;
    size_t touchedCount = 0;  // written to touched; a tile read twice in a row is written once
    bool stopAtMissing = false;
    uint64_t missingProbes = 0;  // bilinear probes that found their tile missing
    uint8_t* queryMissed =
        nullptr;  // caller's buffer, one per query: 1 where it found a tile missing
};

// Where a batch of probes writes its n-tuples: interleaved, query k's channels at
// interleaved + k * channels, or one row per channel, channel c of query k at rows[c][k]
// (the layout a shading batch reads, with no transposing pass). Exactly one is set.
struct ProbeOutput {
    float* interleaved = nullptr;
    float* const* rows = nullptr;  // map.channels() rows of queries.size() floats
};

void probeShaderMap(const ShaderMap& map, const ProbeOptions& options,
                    std::span<const ProbeQuery> queries, ProbeOutput out,
                    ProbeResidency* residency = nullptr);

// Writes queries.size() * map.channels() floats to out, query by query.
inline void probeShaderMap(const ShaderMap& map, const ProbeOptions& options,
                           std::span<const ProbeQuery> queries, float* out,
                           ProbeResidency* residency = nullptr) {
    probeShaderMap(map, options, queries, ProbeOutput{out, nullptr}, residency);
}

}  // namespace mpshade
