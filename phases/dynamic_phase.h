// dynamic_phase.h -- the patent's dynamic phase (FIG. 2, 230): every frame, over read-only
// object representations, the dynamic TSI (the fixed-point warp, fixed_point_warp.h, and
// rasterization to a visibility buffer, facet_rasterizer.h) and the dynamic shader on
// what each sample sees (surface_points.h), composited front to back and filtered into
// pixels.
//
// Shading runs in bands of pixel rows, in parallel. A band whose probes find shader-map
// tiles is left unshaded and the tiles are handed back, so a caller wanting constant
// quality fills them and calls shade() again (only those bands are redone); a caller
// keeping a frame rate accepts the coarser levels instead (acceptFallbacks).
//
// Shading rate. Per sample: every visible surface of every sample is a shading point at
// that sample. Per pixel: the samples of a pixel that see the same object (at the same
// depth layer) share one shading point at their centroid, on the facet of the sample
// nearest to it; coverage stays per sample, so edges are as antialiased as the
// reference's, while the dynamic shader and the probes run about spp times less often.
// The probe footprint is 1/sqrt(spp) pixel per sample (the sample's stratum), and half a
// pixel per pixel, times footprintScale.
#pragma once

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "phases/band_points.h"
#include "phases/facet_rasterizer.h"
#include "phases/object_representation.h"
#include "phases/phase_trace.h"
#include "phases/sample_pattern.h"
#include "phases/scene_resources.h"
#include "phases/surface_points.h"
#include "phases/view_reuse.h"

namespace mpshade {

struct DynamicOptions {
    RasterOptions raster;
    // Feline capped at 2:1 by shortening the major axis (the samples integrate along it),
    // one tap per unit of anisotropy, two levels blended only within 1/16 level of their
    // midpoint. Over the courtyard's 24 frames, blending within 1/8 level filled 12% more
    // texels and took 12% more taps for 0.03 dB; the nearest level alone 21% fewer than
    // that, but cost 0.06 dB. With the footprint below, measured within 0.5 dB of the
    // reference renderer against 64-sample references on every example
    // (docs/multiphase.md). Footprints more eccentric than 12:1 read no finer a level than
    // major / 12: on the grazing floor (tests/data/scenes/grazing_floor.json, 240x135, 12
    // frames) 54% fewer texels filled and the whole sequence 1.9x faster for 0.05 dB, on
    // the examples within 0.02 dB (8:1 lost 0.2 dB on the courtyard; docs/shader-maps.md).
    ProbeOptions probe{ProbeFilter::Feline, 2.0f, 0.125f, 1.0f, AnisotropyCap::ShrinkMajor, 12.0f};
    ShadingRate shadingRate = ShadingRate::Sample;
    // Multiplies each shading point's probe footprint of 1/sqrt(spp) pixel per sample (its
    // stratum), or half a pixel per pixel.
    float footprintScale = 1.0f;
    // Per object (by scene index), a further multiplier of its points' footprints, as the
    // controller's footprint calibration chooses them (controller/footprint_calibration.h);
    // objects past the end, or all when empty: 1.
    std::vector<float> objectFootprint;
    int bandRows = 4;  // pixel rows per unit of shading work
    // Per pixel or 2x2 pixels: a pixel (block) whose samples all see one surface in front
    // takes its point from the layout's precomputed centroid and nearest sample instead of
    // grouping its fragments; the same points, bit for bit (tested with this off).
    bool wholePixelShortcut = true;
    // Where the warp, rasterization, shading bands and resolve report their spans (not
    // owned; null: nowhere).
    PhaseTrace* trace = nullptr;
    // Past this moment rasterization and shading stop where they are (abandoned()): for a
    // dynamic phase worth less than a deadline, as a prediction in a frame's slack is
    // (overrides raster.deadline). Default never.
    std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();
    // A frame that sees the scene exactly as the last one did (the same camera, placements,
    // representations, layout and the options above) runs the dynamic shader alone, on
    // the inputs each band kept (view_reuse.h): the same bits as shading afresh. Bands keep
    // them at a frame whose view held still since the last (or at the first), up to this
    // many bytes in all (about 60 a shading point); 0: never.
    size_t reuseBytes = size_t{256} << 20;
    // Whether a run's first frame keeps its inputs too, for a view expected to hold still;
    // false: only a frame whose view held still since an earlier frame keeps them. A frame
    // rendered again (play's first, after its pre-roll rendered it at each step) counts as a
    // first frame here. A camera that
    // moves from the first frame would pay for inputs it never replays: keeping them was
    // 15-30 ms of a warm vase's first frame (its whole sequence 1.29-1.30x its steady
    // frames against 1.21x, side by side).
    bool keepFirstView = true;
};

// A shading point's probe footprint in pixels at `rate` with `spp` samples per pixel, before
// DynamicOptions::footprintScale: a sample's stratum, half a pixel, or a pixel.
inline float footprintPixels(ShadingRate rate, int spp) {
    return rate == ShadingRate::Sample ? 1.0f / std::sqrt(static_cast<float>(spp))
                                       : (rate == ShadingRate::Pixel ? 0.5f : 1.0f);
}

// Object i's entry of a per-object footprint multiplier (DynamicOptions::objectFootprint).
inline float objectFootprintAt(std::span<const float> scales, size_t i) {
    return i < scales.size() ? scales[i] : 1.0f;
}

// What one object cost this frame.
struct ObjectFrameCost {
    bool drawn = false;
    uint64_t facets = 0;  // in its representation
    uint64_t verticesWarped = 0;
    uint64_t shadingPoints = 0;  // runs of the dynamic shader
    uint64_t instructions = 0;   // dynamic shader instructions, times lanes
    double shadeSeconds = 0.0;   // probing and shading its points, summed over threads
    uint64_t probes = 0, probeFallbacks = 0;
    uint64_t tilesMissing = 0;    // distinct tiles its probes asked for that were not resident
    uint64_t pointsReplayed = 0;  // of shadingPoints: shaded on inputs kept from the last frame
    // Combined representation: the longest projected facet edge among its visible
    // clusters, in pixels (the static phase dices again beyond maxEdgePixels).
    float longestEdgePixels = 0.0f;
};

// What the dynamic phase did in a frame: its stages' wall times, the facets of the drawn
// objects' representations (count, vertices warped, bytes of facets and attributes), the
// rasterizer's counts, and the shading passes (shade() calls) with the points shaded, the
// dynamic shader's instructions (times lanes), the results that were not finite and were
// zeroed, and the bilinear probes, of them answered from a coarser level.
struct DynamicFrameStats {
    double warpSeconds = 0.0, rasterSeconds = 0.0, shadeSeconds = 0.0, resolveSeconds = 0.0;
    // Where shading's time went, CPU seconds summed over the threads (so over the cores, not
    // wall time): making the bands' points from the visibility; their positions, view
    // directions, interpolated attributes and chart footprints; probing the shader maps;
    // the dynamic shader (with its results made finite); compositing the samples.
    struct ShadeParts {
        double points = 0.0, interpolate = 0.0, probe = 0.0, kernel = 0.0, composite = 0.0;
        ShadeParts& operator+=(const ShadeParts& o) {
            points += o.points, interpolate += o.interpolate, probe += o.probe;
            kernel += o.kernel, composite += o.composite;
            return *this;
        }
    } shadeParts;
    int shadePasses = 0;
    uint64_t facets = 0, verticesWarped = 0, facetBytes = 0;
    RasterStats raster;
    uint64_t shadingPoints = 0, instructions = 0, nonFinite = 0;
    uint64_t probes = 0, probeFallbacks = 0;
    // The frame saw what the last one did and reused its visibility (no warp, no
    // rasterization); of shadingPoints, those shaded on kept inputs.
    bool viewReused = false;
    uint64_t pointsReplayed = 0;

    // The phase's wall time on the rendering thread: warp, rasterize, shade, resolve.
    double seconds() const { return warpSeconds + rasterSeconds + shadeSeconds + resolveSeconds; }
    DynamicFrameStats& operator+=(const DynamicFrameStats& o) {
        warpSeconds += o.warpSeconds;
        rasterSeconds += o.rasterSeconds;
        shadeSeconds += o.shadeSeconds;
        resolveSeconds += o.resolveSeconds;
        shadeParts += o.shadeParts;
        shadePasses += o.shadePasses;
        facets += o.facets;
        verticesWarped += o.verticesWarped;
        facetBytes += o.facetBytes;
        raster += o.raster;
        shadingPoints += o.shadingPoints;
        instructions += o.instructions;
        nonFinite += o.nonFinite;
        probes += o.probes;
        probeFallbacks += o.probeFallbacks;
        viewReused = viewReused || o.viewReused;
        pointsReplayed += o.pointsReplayed;
        return *this;
    }
};

// One pass of DynamicPhase::refine().
struct RefinePass {
    ShadingRate rate = ShadingRate::Sample;
    float footprintScale = 1.0f;  // times footprintPixels(rate, spp), as DynamicOptions'
    // No tile starts after this moment; one started is finished.
    std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();
    // Per object, multiplies footprintScale for its points; empty: the frame's
    // (DynamicOptions::objectFootprint). Not owned; read during refine() only.
    std::span<const float> objectFootprint{};
};

// What a refine() pass did: the first `tiles` of those asked were shaded again, at so many
// points and bilinear probes, of them so many answered from a coarser level.
struct RefineCounts {
    size_t tiles = 0;
    uint64_t shadingPoints = 0, probes = 0, probeFallbacks = 0;
};

class DynamicPhase {
  public:
    explicit DynamicPhase(const Scene& scene);
    ~DynamicPhase();
    DynamicPhase(const DynamicPhase&) = delete;
    DynamicPhase& operator=(const DynamicPhase&) = delete;

    // Starts a frame: warps and rasterizes every object that has a representation (null:
    // not drawn this frame). The representations, the frame state and the layout must
    // stay alive and unchanged until finish().
    void begin(const FrameState& frame, std::span<const ObjectRepresentation* const> objects,
               std::shared_ptr<const SampleLayout> layout, const DynamicOptions& options);
    // Shades the bands not yet shaded. Returns the missing tiles, deduplicated; with
    // acceptFallbacks every band is done (missing tiles fell back to coarser levels),
    // otherwise bands that missed tiles stay undone until a later call.
    std::vector<TileRequest> shade(bool acceptFallbacks = false);
    bool complete() const;
    // The deadline passed first: rasterization stopped short (the frame cannot be shaded),
    // or shade() left bands undone.
    bool abandoned() const { return abandoned_; }
    // The composited samples (after shade() completed every band).
    const SampleBuffer& samples() const { return samples_; }
    // Per pixel: 1 where its samples all came out alike and only its first was written.
    std::span<const uint8_t> uniformPixels() const { return uniform_; }
    // The composited samples and uniform marks, kept before trial refine() passes and put
    // back after them, so the frame is the one its own pass shaded. Restoring needs a copy
    // kept from this frame (same size).
    struct KeptSamples {
        std::vector<float> rgba;
        std::vector<uint8_t> uniform;
    };
    KeptSamples keepSamples() const { return {samples_.rgba, uniform_}; }
    void restoreSamples(const KeptSamples& kept);
    // Filters the samples into pixels.
    void resolve(Image& out);

    // After shade() completed every band: shades the pixels of `tiles` again, in their
    // order, at the pass's rate and footprint, with fallbacks (a missing tile reads a
    // coarser level and is appended to `missing`), each tile's samples composited anew.
    // Tiles are taken in order by every thread and none starts after the pass's deadline,
    // so those done are always a prefix. resolveAgain() or resolveRects() then makes the
    // pixels.
    // The frame's own stats (stats(), objectCosts()) are left as shade() made them.
    RefineCounts refine(std::span<const PixelRect> tiles, const RefinePass& pass,
                        std::vector<TileRequest>& missing);
    // resolve() again after refine(); returns its seconds (stats() keeps the first's).
    double resolveAgain(Image& out);
    // The same for the pixels that read samples of `changed` alone (the tiles refine() did:
    // SampleLayout::pixelsReading, resolveRects; the same bits), the rest of `out` left as
    // resolve() made it; returns its seconds.
    double resolveAgain(Image& out, std::span<const PixelRect> changed);

    const DynamicFrameStats& stats() const { return stats_; }
    const std::vector<ObjectFrameCost>& objectCosts() const { return costs_; }
    const VisibilityBuffer& visibility() const { return visibility_; }
    // The last frame's sample layout (null before the first) and how its bands made their
    // shading points from the visibility buffer.
    const SampleLayout* layout() const { return layout_.get(); }
    BandPointOptions pointOptions() const {
        return {options_.shadingRate, options_.wholePixelShortcut};
    }

  private:
    struct Band;
    void compareWithLastView();
    void warpObjects();
    void rasterizeObjects();
    void prepareBands();
    void shadeBand(size_t band, bool acceptFallbacks, std::vector<TileRequest>& missing);
    // Composites a band whose points are all shaded, counts them in `costs` (per object) and
    // adds the composite's time to `parts`.
    void finishBand(size_t band, const BandRange& range, const BandPoints& pts,
                    std::vector<ObjectFrameCost>& costs, DynamicFrameStats::ShadeParts& parts);

    const Scene& scene_;
    const FrameState* frame_ = nullptr;
    std::vector<const ObjectRepresentation*> objects_;
    std::shared_ptr<const SampleLayout> layout_;
    DynamicOptions options_;
    FacetRasterizer rasterizer_;
    std::vector<std::unique_ptr<FixedPointWarp>> warps_;
    std::vector<WarpedVertices> warped_;
    std::vector<std::vector<uint8_t>> clusterVisible_;
    std::vector<uint8_t> cullBack_;  // per object this frame: back faces hidden
    std::vector<ObjectView> views_;
    VisibilityBuffer visibility_;
    SampleBuffer samples_;
    std::vector<uint8_t> uniform_;  // per pixel: every sample alike
    std::vector<uint8_t> bandDone_;
    bool abandoned_ = false;
    std::unique_ptr<Band> scratch_;
    std::vector<ObjectView> refineViews_;  // views_ at a refine pass's footprint
    // The last frame's view (view_reuse.h); whether its visibility is whole; whether this
    // frame reuses it, and whether its bands keep their inputs.
    ViewKey lastView_;
    int lastViewFrame_ = -1;  // the frame index lastView_ was of
    bool haveLastView_ = false, lastViewWhole_ = false;
    bool reusing_ = false, keeping_ = false;
    InputLayout inputLayout_;
    std::atomic<size_t> keptBytes_{0};
    DynamicFrameStats stats_;
    std::vector<ObjectFrameCost> costs_;
};

}  // namespace mpshade
