// map_precision.h -- whether an object's shader map may store its channels as binary16
// ("shadermap_precision": "auto", the default): half the bytes of every tile, so probes read
// half the memory and a budget or a store holds twice the tiles.
//
// binary16 keeps a value to 2^-11 of its magnitude and up to 65504 (half_float.h). Whether
// that shows depends on the shader: a colour the dynamic part scales by its lighting keeps
// the 2^-11 in its result, while a stored phase the dynamic part takes the sine of, or a
// value past the range, does not. So it is measured, not guessed: at points spread over the
// object's charts (one grid a chart, as `factor --verify` spreads them), the static part runs
// once, then the dynamic part twice at the same view -- with the channels as computed and
// with each rounded to binary16 -- and half is chosen only when no output moves by more than
// `tolerance` of max(|value|, 1) and no channel value seen exceeds `maxValue`, 16 times below
// half's range, for the values between the points.
//
// Measured on frames as `render` makes them (one thread, docs/shader-maps.md): the probe's
// share of shading 8-18% smaller on the vase, gallery and courtyard with half maps, and
// the images within 0.001 dB of float maps against the reference.
#pragma once

#include <cstddef>
#include <string>

#include "geometry/content_digest.h"
#include "geometry/surface.h"
#include "shading/interpreter.h"

namespace mpshade {

class StaticPhase;
class TileStore;

struct MapPrecisionOptions {
    int points = 256;  // at most, spread as a grid over each chart (at least one a chart)
    // Largest change of an output (Ci, Oi) allowed, relative to max(|value|, 1). 2^-9 lets a
    // few roundings of 2^-11 through a product (a stored colour times a stored occlusion),
    // and is a tenth of an 8-bit step at 1.
    double tolerance = 1.0 / 512.0;
    double maxValue = 4096.0;  // largest |channel value| at the points (half's limit 65504)
};

struct MapPrecisionCheck {
    bool half = false;
    int points = 0;
    double largestValue = 0.0;   // largest finite |channel value| at the points
    double largestChange = 0.0;  // of the outputs, relative to max(|value|, 1); inf: not finite
    std::string reason;          // why, for reports
};

// The check for object `object` of the scene `statics` was made for, its static part run with
// `uniforms` (those the map would be filled with) and its dynamic part at the same view.
// Objects without channels are never half.
MapPrecisionCheck checkHalfPrecision(const StaticPhase& statics, const Surface& surface,
                                     size_t object, const ShadingUniforms& uniforms,
                                     const MapPrecisionOptions& options = {});

// The same, its verdict kept in `store` (may be null) as a record under `key` (a digest of
// everything the check depends on) and read back from there when present: a run whose
// tiles all come from a store does not run the static part to decide.
MapPrecisionCheck checkHalfPrecisionKept(const StaticPhase& statics, const Surface& surface,
                                         size_t object, const ShadingUniforms& uniforms,
                                         const MapPrecisionOptions& options, TileStore* store,
                                         const Digest128& key);

}  // namespace mpshade
