// footprint_calibration.h -- each object's probe footprint chosen from measured error, not
// one scale for the scene (docs/shader-maps.md, "Footprints by object").
//
// A shader-map probe reads the level whose texels match its shading point's footprint
// (dynamic_phase.h: a sample's stratum at per-sample shading). A wider footprint reads a
// coarser level: a quarter of the texels to fill per doubling, and fewer probe taps, for a
// blurrier static part. Whether the image can tell depends on the object: a static part
// with little detail at the finest levels loses nothing, veined marble loses its veins.
// Measured at 480x270 against 64-sample references, footprint x1.41 everywhere left the
// vase and the gallery within 0.2 dB of the reference renderer and cost the teapot 2 dB.
//
// So the first constant-quality frame that shows an object well measures it (unless the
// view holds still: its later frames replay their probed inputs, and gain nothing; or too
// few frames follow to repay the measuring). Over a checkerboard of image tiles, the
// frame's points are shaded again at candidate scales (DynamicPhase::refine), each object
// at its own candidate, found by bisection over the candidates (three passes for six), and
// resolved; over the pixels the object alone covers inside those tiles (away from their
// edges, which the filter mixes with tiles left as they were), the squared change from the
// frame at scale 1 is set against the frame's own sampling noise there: each pixel's
// variance of its samples' mean, the error a few-sample renderer's pixel carries anyway
// (the reference renderer's included). The object takes the largest candidate whose change
// stays within `tolerance` of that noise, plus `floor` a pixel, so that an object without
// noise (a flat colour) widens freely, from the next frame on (the measured frame keeps the
// samples its own pass shaded). Hakura and Snyder's layers make the same trade per layer,
// at their error's cost.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "phases/facet_rasterizer.h"
#include "phases/image.h"
#include "phases/sample_pattern.h"

namespace mpshade {

struct FootprintCalibrationOptions {
    bool enabled = true;
    // Candidate multipliers of an object's footprint, ascending, each above 1 (2^(1/3),
    // 2^(2/3), 2: a third of a level apart).
    std::vector<float> scales{1.12f, 1.26f, 1.41f, 1.59f, 1.78f, 2.0f};
    // An object's squared change over its pixels may reach this share of their noise. Its
    // error against a converged image rose by 0.4-1.0 times the change on the examples; at
    // 480x270 against 64-sample references, 0.05 cost 0.03-0.12 dB on the courtyard, the
    // gallery, the vase and a camera dolly, and 0.1 cost up to 0.41 dB (docs/shader-maps.md).
    double tolerance = 0.05;
    // Squared change a pixel may have whatever its noise (RGB mean; 1e-6 is 60 dB).
    double floor = 1e-6;
    // An object is measured at the first frame where it alone covers this many pixels; until
    // then, and if it never does, its footprint stays at 1.
    int minPixels = 256;
    // Measured only at a frame with at least this many frames planned from it on (itself
    // included): measuring costs its frame 0.03-0.2 s at 480x270 on 2 cores, repaid after
    // 17-30 frames on the courtyard, the gallery, the vase and a camera dolly
    // (docs/shader-maps.md).
    int minFrames = 24;
    // Image tiles measured: those of a checkerboard of tiles this many pixels a side.
    int tileSize = 32;
};

// What calibration measured of one object, over the pixels it alone covers.
struct FootprintMeasure {
    uint64_t pixels = 0;
    double noise = 0.0;  // sum of each pixel's variance of its samples' mean (RGB mean)
    // The candidate scales tried, in the order tried, and each one's sum of squared changes
    // (RGB mean).
    std::vector<float> scales;
    std::vector<double> change;
};

// Per pixel of the visibility buffer: the object whose surface every sample of the pixel
// sees in front, or -1 (samples that see nothing or differ, or a surface of another object
// seen by a sample of a pixel within `margin` pixels, the filter's reach, in any layer).
// `pixels`, per object (resized to `objects`): how many pixels it owns.
std::vector<int32_t> pixelOwners(const VisibilityBuffer& vis, size_t objects, int margin,
                                 std::vector<uint64_t>& pixels);

// Adds each owned pixel's sampling noise to its owner's measure: the unbiased variance of its
// samples (RGB mean) over the samples per pixel. Pixels `uniform` marks (their samples alike,
// only the first written) have none. Needs at least 2 samples per pixel (else adds nothing).
void addSampleNoise(const SampleBuffer& samples, std::span<const uint8_t> uniform,
                    std::span<const int32_t> owners, std::vector<FootprintMeasure>& measures);

// Appends to the measure of each object in `objects` (by index) the scale it was shaded at
// (`scales`, per object) and the squared change between `image` and `base` over its owned
// pixels.
void addChange(const Image& image, const Image& base, std::span<const int32_t> owners,
               std::span<const size_t> objects, std::span<const float> scales,
               std::vector<FootprintMeasure>& measures);

// Whether the k-th change is within the options' tolerance of the noise.
bool changeAllowed(const FootprintMeasure& m, size_t k, const FootprintCalibrationOptions& o);

// The scale chosen: the largest scale tried whose change is allowed and below every scale
// tried whose change is not; 1 if none.
float chosenFootprint(const FootprintMeasure& m, const FootprintCalibrationOptions& o);

// `owners` left only where the pixel lies in a tile of the checkerboard of `tileSize`-pixel
// tiles whose corner tile is in it, at least `margin` pixels inside the tile's edges that
// face the image (the filter's reach: those pixels read only samples of their tile).
void keepCheckerboard(std::vector<int32_t>& owners, int width, int height, int tileSize,
                      int margin);

// The image tiles (tileSize pixels a side, clipped to the image) holding a pixel owned by
// one of `objects`, in row order.
std::vector<PixelRect> tilesOwnedBy(std::span<const int32_t> owners, int width, int height,
                                    std::span<const size_t> objects, int tileSize);

}  // namespace mpshade
