// fixed_point_warp.h -- the dynamic TSI's transform (patent col. 5 and claim 26): each
// frame, one float object-to-screen matrix per object becomes an integer matrix, and the
// facets' 16-bit vertices go to 8-bit sub-pixel screen coordinates with integer
// arithmetic only.
//
// Bit budget. The screen position is x = X / W with X = x_px * W and W the view depth,
// both linear in the quantized vertex q (0 <= q_i < 2^16):
//   X = sum_i L_i q_i + T    (likewise Y and W),
// with L_i = M_i * step_i and T = M(origin) from the float matrix M. All coefficients are
// scaled by one power of two 2^s and rounded to int64:
//   * s is the largest shift with |L_i| 2^s <= 2^40 and |T| 2^s <= 2^61, so each product
//     L_i q_i fits in 56 bits and X, Y, W in 62 bits: no int64 overflow, for any matrix.
//   * A vertex is kept only if W >= near (in the same scale) and |X|, |Y| < 2^15 W (a
//     guard band of 32768 pixels); then x_fixed = (X << 8) / W is at most 2^23 in
//     magnitude and fits int32; the 71-bit numerator is formed in __int128.
// Error. Rounding each coefficient costs at most 1/2 unit of 2^-s, so |dX|, |dW| <=
// (3 * 65535 + 1) / 2 units, and the screen error is at most
//   (|dX| + |x| |dW|) / (W 2^s) pixels,
// plus 1/512 pixel from rounding x to 8 fractional bits. errorBound() evaluates this at
// the object's nearest depth and the image's widest coordinate; the tests check the
// measured error against 1/16 pixel over the valid range.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/mat4x4.hpp>

#include "phases/facet_mesh.h"
#include "scene/scene_state.h"

namespace mpshade {

struct WarpedVertices {
    std::vector<int32_t> x, y;    // pixels, 8 fractional bits (value / 256 = pixel coordinate)
    std::vector<float> depth;     // view depth W, world units
    std::vector<uint8_t> culled;  // behind the near plane or outside the guard band
    void resize(size_t n);
};

class FixedPointWarp {
  public:
    static constexpr int kSubpixelBits = 8;
    static constexpr int kGuardBandBits = 15;

    // objectToWorld places the mesh; camera gives the screen. Bounds: the mesh's format
    // covers the quantized box, whose corners bound W.
    FixedPointWarp(const glm::mat4& objectToWorld, const CameraState& camera,
                   const FixedPointFormat& format);

    void warp(const uint16_t* qx, const uint16_t* qy, const uint16_t* qz, size_t n,
              WarpedVertices& out) const;

    // The same transform in double precision: the reference the fixed-point path is
    // measured against. Returns false behind the near plane.
    bool warpExact(uint16_t qx, uint16_t qy, uint16_t qz, double& x, double& y) const;

    int shift() const { return shift_; }
    // A bound on the screen error, in pixels, for vertices in front of the near plane.
    double errorBound() const { return errorBound_; }

  private:
    double m_[3][4];        // object -> (X, Y, W), double
    int64_t l_[3][3] = {};  // scaled coefficients of q
    int64_t t_[3] = {};     // scaled translations
    int64_t nearW_ = 1;
    int shift_ = 0;
    double errorBound_ = 0.0;
    FixedPointFormat format_;
};

}  // namespace mpshade
