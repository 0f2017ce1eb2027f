// fixed_point_warp.h -- the dynamic TSI's transform (patent col. 5 and claim 26): each
// frame, one float object-to-screen matrix per object becomes an integer matrix, and the
// facets' 16-bit vertices go to 8-bit sub-pixel screen coordinates with integer
// arithmetic.
//
// Bit budget. The screen position is x = X / W with X = x_px * W and W the view depth,
// both linear in the quantized vertex q (0 <= q_i < 2^16):
//   X = sum_i L_i q_i + T    (likewise Y and W),
// with L_i = M_i * step_i and T = M(origin) from the float matrix M. All coefficients are
// scaled by one power of two 2^s and rounded to integers:
//   * s is the largest shift with |L_i| 2^s <= 2^35 and |T| 2^s <= 2^51, so each product
//     L_i q_i is an integer below 2^51 in magnitude and every partial sum of X, Y, W is an
//     integer below 2^53. Such integers are exact in IEEE double, so the integer sums are
//     carried in double lanes -- exactly, for any matrix, and vectorized -- rather than in
//     int64 (which has no vector multiply on x86) or int128.
//   * A vertex is kept only if W >= near (in the same scale) and |X|, |Y| < 2^15 W (a
//     guard band of 32768 pixels). Then X 256 / W is below 2^23 in magnitude; it is formed
//     as (X 256) (1 / W) -- X 256 is exact (a power-of-two scaling), the reciprocal and the
//     product each round once, so it is within 2^-28 of the true quotient -- and rounded to
//     the nearest integer (ties to even): deterministic, and off by at most 1/2 + 2^-28
//     units of 1/256 pixel, where the 128-bit integer division it replaces truncated, off
//     by up to one unit.
// Error. Rounding each coefficient costs at most 1/2 unit of 2^-s, so |dX|, |dW| <=
// (3 * 65535 + 1) / 2 units, and the screen error is at most
//   (|dX| + |x| |dW|) / (W 2^s) pixels,
// plus 1/512 + 2^-36 pixel from rounding x to 8 fractional bits. errorBound() evaluates
// this at the object's nearest depth and the image's widest coordinate; the tests check
// the measured error against it and against 1/16 pixel over the valid range.
#pragma once

#include <climits>
#include <cstdint>
#include <vector>

#include <glm/mat4x4.hpp>

#include "phases/facet_mesh.h"
#include "scene/scene_state.h"

namespace mpshade {

struct WarpedVertices {
    // x of a vertex behind the near plane or outside the guard band (never a real value:
    // real ones are within 2^23 of zero).
    static constexpr int32_t kCulled = INT32_MIN;
    std::vector<int32_t> x, y;    // pixels, 8 fractional bits (value / 256 = pixel coordinate)
    std::vector<float> invDepth;  // 1 / W, W the view depth in world units
    void resize(size_t n);
    bool culled(size_t i) const { return x[i] == kCulled; }
};

// A vertex in homogeneous screen coordinates: x_px = X / W, y_px = Y / W, W the view depth
// (world units). Double precision; for clipping facets that cross the near plane or the
// guard band.
struct HomogeneousVertex {
    double X = 0.0, Y = 0.0, W = 0.0;
};

// The object-to-screen transform of a camera in homogeneous form: rows giving X, Y and W
// (x_px = X / W, y_px = Y / W, W the view depth in world units) from object coordinates
// (x, y, z, 1).
void objectToScreen(const glm::mat4& objectToWorld, const CameraState& camera, double rows[3][4]);

class FixedPointWarp {
  public:
    static constexpr int kSubpixelBits = 8;
    static constexpr int kGuardBandBits = 15;
    static constexpr double kGuardBand = 32768.0;  // pixels, 2^kGuardBandBits

    // objectToWorld places the mesh; camera gives the screen. Bounds: the mesh's format
    // covers the quantized box, whose corners bound W.
    FixedPointWarp(const glm::mat4& objectToWorld, const CameraState& camera,
                   const FixedPointFormat& format);

    void warp(const uint16_t* qx, const uint16_t* qy, const uint16_t* qz, size_t n,
              WarpedVertices& out) const;

    // The vertex in homogeneous screen coordinates, from the same integer coefficients
    // the warp uses (so clipped and unclipped facets agree on shared vertices).
    HomogeneousVertex homogeneous(uint16_t qx, uint16_t qy, uint16_t qz) const;
    // The near plane's depth in the scale of homogeneous().
    double nearDepth() const { return nearW_ * invScale_; }

    // The same transform in double precision from the float matrix: the reference the
    // fixed-point path is measured against. Returns false behind the near plane.
    bool warpExact(uint16_t qx, uint16_t qy, uint16_t qz, double& x, double& y) const;

    int shift() const { return shift_; }
    // A bound on the screen error, in pixels, for vertices in front of the near plane.
    double errorBound() const { return errorBound_; }

  private:
    double m_[3][4];       // object -> (X, Y, W), double
    double l_[3][3] = {};  // scaled coefficients of q: integers, |l| <= 2^35
    double t_[3] = {};     // scaled translations: integers, |t| <= 2^51
    double nearW_ = 1.0;   // the near plane, scaled: an integer
    double invScale_ = 1.0;
    int shift_ = 0;
    double errorBound_ = 0.0;
    FixedPointFormat format_;
};

}  // namespace mpshade
