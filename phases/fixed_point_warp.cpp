#include "phases/fixed_point_warp.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "geometry/error.h"

namespace mpshade {
namespace {

// Round to the nearest integer, ties to even, for |v| < 2^51: adding 1.5 * 2^52 leaves
// no fractional bits, and the addition rounds to nearest-even. One add and one subtract
// in any vector width (no SSE4.1 round instruction needed).
inline double roundToInteger(double v) {
    constexpr double kMagic = 6755399441055744.0;  // 1.5 * 2^52
    return (v + kMagic) - kMagic;
}

}  // namespace

void WarpedVertices::resize(size_t n) {
    x.resize(n);
    y.resize(n);
    invDepth.resize(n);
    culled.resize(n);
}

void objectToScreen(const glm::mat4& objectToWorld, const CameraState& camera, double out[3][4]) {
    // World -> (X, Y, W): W = forward . (p - eye), X = x_px W, Y = y_px W.
    const double w2 = camera.width * 0.5, h2 = camera.height * 0.5;
    const double th = camera.tanHalfFovY, ta = camera.tanHalfFovY * camera.aspect;
    const glm::dvec3 eye(camera.eye), f(camera.forward), r(camera.right), u(camera.up);
    double rows[3][4];
    for (int k = 0; k < 3; ++k) {
        rows[0][k] = w2 * (f[k] + r[k] / ta);
        rows[1][k] = h2 * (f[k] - u[k] / th);
        rows[2][k] = f[k];
    }
    rows[0][3] = -w2 * (glm::dot(f, eye) + glm::dot(r, eye) / ta);
    rows[1][3] = -h2 * (glm::dot(f, eye) - glm::dot(u, eye) / th);
    rows[2][3] = -glm::dot(f, eye);
    // Compose with object -> world.
    const glm::dmat4 o(objectToWorld);
    for (int row = 0; row < 3; ++row)
        for (int c = 0; c < 4; ++c) {
            double s = c == 3 ? rows[row][3] : 0.0;
            for (int k = 0; k < 3; ++k) s += rows[row][k] * o[c][k];
            out[row][c] = s;
        }
}

FixedPointWarp::FixedPointWarp(const glm::mat4& objectToWorld, const CameraState& camera,
                               const FixedPointFormat& format)
    : format_(format) {
    objectToScreen(objectToWorld, camera, m_);
    // Coefficients of q, and the translation at the quantization origin.
    double l[3][3], t[3], maxL = 0.0, maxT = 0.0;
    for (int row = 0; row < 3; ++row) {
        t[row] = m_[row][3];
        for (int k = 0; k < 3; ++k) {
            l[row][k] = m_[row][k] * format.step[k];
            t[row] += m_[row][k] * format.origin[k];
            maxL = std::max(maxL, std::fabs(l[row][k]));
        }
        maxT = std::max(maxT, std::fabs(t[row]));
    }
    auto log2up = [](double v) {
        return v > 0.0 ? static_cast<int>(std::ceil(std::log2(v))) : -1000;
    };
    shift_ = std::min(35 - log2up(maxL), 51 - log2up(maxT));
    shift_ = std::clamp(shift_, -900, 900);
    const double scale = std::ldexp(1.0, shift_);
    invScale_ = std::ldexp(1.0, -shift_);
    for (int row = 0; row < 3; ++row) {
        t_[row] = std::nearbyint(t[row] * scale);
        for (int k = 0; k < 3; ++k) l_[row][k] = std::nearbyint(l[row][k] * scale);
    }
    nearW_ = std::max(1.0, std::ceil(static_cast<double>(camera.zNear) * scale));

    // The bound at the object's nearest depth in front of the near plane.
    double minW = 1e300;
    for (int corner = 0; corner < 8; ++corner) {
        const double q[3] = {(corner & 1) ? 65535.0 : 0.0, (corner & 2) ? 65535.0 : 0.0,
                             (corner & 4) ? 65535.0 : 0.0};
        double w = t[2];
        for (int k = 0; k < 3; ++k) w += l[2][k] * q[k];
        minW = std::min(minW, w);
    }
    minW = std::max(minW, static_cast<double>(camera.zNear));
    const double roundingUnits = 0.5 * (3.0 * 65535.0 + 1.0);
    const double widest = std::max(camera.width, camera.height);
    errorBound_ = roundingUnits * (1.0 + widest) / (minW * scale) + 1.0 / 512.0 + std::ldexp(1.0, -38);
}

void FixedPointWarp::warp(const uint16_t* qx, const uint16_t* qy, const uint16_t* qz, size_t n,
                          WarpedVertices& out) const {
    out.resize(n);
    const double l00 = l_[0][0], l01 = l_[0][1], l02 = l_[0][2], t0 = t_[0];
    const double l10 = l_[1][0], l11 = l_[1][1], l12 = l_[1][2], t1 = t_[1];
    const double l20 = l_[2][0], l21 = l_[2][1], l22 = l_[2][2], t2 = t_[2];
    const double nearW = nearW_, guard = kGuardBand, scale = std::ldexp(1.0, shift_);
    int32_t* ox = out.x.data();
    int32_t* oy = out.y.data();
    float* oinv = out.invDepth.data();
    uint8_t* oc = out.culled.data();
    // Every operation below is on doubles holding integers under 2^53 (see the header),
    // so the sums are exact in any evaluation order and the loop vectorizes.
    for (size_t i = 0; i < n; ++i) {
        const double a = qx[i], b = qy[i], c = qz[i];
        const double X = l00 * a + l01 * b + l02 * c + t0;
        const double Y = l10 * a + l11 * b + l12 * c + t1;
        const double W = l20 * a + l21 * b + l22 * c + t2;
        const double band = guard * W;
        const bool keep = W >= nearW && X < band && X > -band && Y < band && Y > -band;
        const double safeW = keep ? W : 1.0;
        const double sx = keep ? roundToInteger(X * 256.0 / safeW) : 0.0;
        const double sy = keep ? roundToInteger(Y * 256.0 / safeW) : 0.0;
        ox[i] = static_cast<int32_t>(sx);
        oy[i] = static_cast<int32_t>(sy);
        oinv[i] = keep ? static_cast<float>(scale / W) : 0.0f;
        oc[i] = keep ? 0 : 1;
    }
}

HomogeneousVertex FixedPointWarp::homogeneous(uint16_t qx, uint16_t qy, uint16_t qz) const {
    const double a = qx, b = qy, c = qz;
    HomogeneousVertex v;
    v.X = (l_[0][0] * a + l_[0][1] * b + l_[0][2] * c + t_[0]) * invScale_;
    v.Y = (l_[1][0] * a + l_[1][1] * b + l_[1][2] * c + t_[1]) * invScale_;
    v.W = (l_[2][0] * a + l_[2][1] * b + l_[2][2] * c + t_[2]) * invScale_;
    return v;
}

bool FixedPointWarp::warpExact(uint16_t qx, uint16_t qy, uint16_t qz, double& x, double& y) const {
    const glm::dvec3 p =
        glm::dvec3(format_.origin) + glm::dvec3(format_.step) * glm::dvec3(qx, qy, qz);
    double h[3];
    for (int row = 0; row < 3; ++row)
        h[row] = m_[row][0] * p.x + m_[row][1] * p.y + m_[row][2] * p.z + m_[row][3];
    if (!(h[2] > 0.0)) return false;
    x = h[0] / h[2];
    y = h[1] / h[2];
    return true;
}

}  // namespace mpshade
