// srgb.h -- 8-bit sRGB encoding of linear values, for the PNG frames.
#pragma once

#include <cstdint>

namespace mpshade {

// round(255 * sRGB(c)) with c clamped to [0, 1] (NaN as 0), sRGB the IEC 61966-2-1 transfer
// function (linear below 0.0031308, 1.055 c^(1/2.4) - 0.055 above), evaluated in float.
uint8_t srgbCodeDirect(float c);

// The same code from tables computed once from srgbCodeDirect (the 255 linear values where
// it steps, and the code at the start of each of 3329 ranges of floats): a look-up and one
// comparison instead of a pow per channel. Equal to srgbCodeDirect for every float.
uint8_t srgbCode(float c);

}  // namespace mpshade
