#include "phases/fixed_point_warp.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <immintrin.h>

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
    errorBound_ =
        roundingUnits * (1.0 + widest) / (minW * scale) + 1.0 / 512.0 + std::ldexp(1.0, -36);
}

namespace {

// Four lanes: one ymm register with AVX2 or AVX-512, two xmm otherwise.
typedef double Double4 __attribute__((vector_size(32)));
typedef long long Mask4 __attribute__((vector_size(32)));
typedef int32_t Int4 __attribute__((vector_size(16)));
typedef float Float4 __attribute__((vector_size(16)));
typedef uint16_t Short4 __attribute__((vector_size(8)));

struct WarpCoefficients {
    double l[3][3], t[3], nearW, guard, scale;
};

// Four vertices at once: the integer sums in double lanes (exact, see the header), then one
// reciprocal and the rounding. Compiled for AVX2 and the baseline, chosen at run time; GCC's
// vector types keep it one source for both.
__attribute__((target_clones("avx2", "default"))) void warpLanes(
    const WarpCoefficients& k, const uint16_t* __restrict qx, const uint16_t* __restrict qy,
    const uint16_t* __restrict qz, size_t n, int32_t* __restrict ox, int32_t* __restrict oy,
    float* __restrict oinv) {
    // The coefficients in locals, so they stay in registers across the stores.
    const double l00 = k.l[0][0], l01 = k.l[0][1], l02 = k.l[0][2], t0 = k.t[0];
    const double l10 = k.l[1][0], l11 = k.l[1][1], l12 = k.l[1][2], t1 = k.t[1];
    const double l20 = k.l[2][0], l21 = k.l[2][1], l22 = k.l[2][2], t2 = k.t[2];
    const double nearW = k.nearW, guard = k.guard, scale = k.scale;
    const double magic = 6755399441055744.0;  // 1.5 * 2^52: adding it rounds to integers
    size_t i = 0;
    for (; i + 4 <= n; i += 4) {
        Short4 sa, sb, sc;
        std::memcpy(&sa, qx + i, sizeof sa);
        std::memcpy(&sb, qy + i, sizeof sb);
        std::memcpy(&sc, qz + i, sizeof sc);
        const Double4 a = __builtin_convertvector(__builtin_convertvector(sa, Int4), Double4);
        const Double4 b = __builtin_convertvector(__builtin_convertvector(sb, Int4), Double4);
        const Double4 c = __builtin_convertvector(__builtin_convertvector(sc, Int4), Double4);
        const Double4 X = l00 * a + l01 * b + l02 * c + t0;
        const Double4 Y = l10 * a + l11 * b + l12 * c + t1;
        const Double4 W = l20 * a + l21 * b + l22 * c + t2;
        const Double4 band = guard * W;
        const Mask4 keep = (W >= nearW) & (X < band) & (X > -band) & (Y < band) & (Y > -band);
        const Double4 r = 1.0 / (keep ? W : Double4{} + 1.0);
        const Double4 sx = keep ? ((X * 256.0 * r + magic) - magic) : Double4{};
        const Double4 sy = keep ? ((Y * 256.0 * r + magic) - magic) : Double4{};
        const Double4 inv = keep ? scale * r : Double4{};
        const Int4 kept = __builtin_convertvector(keep, Int4);
        const Int4 culled = Int4{} + WarpedVertices::kCulled;
        const Int4 ix = kept ? __builtin_convertvector(sx, Int4) : culled;
        const Int4 iy = __builtin_convertvector(sy, Int4);
        const Float4 fi = __builtin_convertvector(inv, Float4);
        std::memcpy(ox + i, &ix, sizeof ix);
        std::memcpy(oy + i, &iy, sizeof iy);
        std::memcpy(oinv + i, &fi, sizeof fi);
    }
    for (; i < n; ++i) {
        const double a = qx[i], b = qy[i], c = qz[i];
        const double X = l00 * a + l01 * b + l02 * c + t0;
        const double Y = l10 * a + l11 * b + l12 * c + t1;
        const double W = l20 * a + l21 * b + l22 * c + t2;
        const double band = guard * W;
        const bool keep = W >= nearW && X < band && X > -band && Y < band && Y > -band;
        const double r = 1.0 / (keep ? W : 1.0);
        ox[i] =
            keep ? static_cast<int32_t>(roundToInteger(X * 256.0 * r)) : WarpedVertices::kCulled;
        oy[i] = keep ? static_cast<int32_t>(roundToInteger(Y * 256.0 * r)) : 0;
        oinv[i] = keep ? static_cast<float>(scale * r) : 0.0f;
    }
}

// GCC 12's AVX-512 headers start conversions from _mm512_undefined_*, which
// -Wmaybe-uninitialized reports as a false positive.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
// The same with AVX-512 intrinsics: eight double lanes, comparison masks in mask registers
// and a masked division (no safe denominator needed), rounding by the instruction.
__attribute__((target("avx512f,avx512vl,avx512dq,avx2"))) void warpAvx512(
    const WarpCoefficients& k, const uint16_t* __restrict qx, const uint16_t* __restrict qy,
    const uint16_t* __restrict qz, size_t n, int32_t* __restrict ox, int32_t* __restrict oy,
    float* __restrict oinv) {
    const __m512d l00 = _mm512_set1_pd(k.l[0][0]), l01 = _mm512_set1_pd(k.l[0][1]),
                  l02 = _mm512_set1_pd(k.l[0][2]), t0 = _mm512_set1_pd(k.t[0]);
    const __m512d l10 = _mm512_set1_pd(k.l[1][0]), l11 = _mm512_set1_pd(k.l[1][1]),
                  l12 = _mm512_set1_pd(k.l[1][2]), t1 = _mm512_set1_pd(k.t[1]);
    const __m512d l20 = _mm512_set1_pd(k.l[2][0]), l21 = _mm512_set1_pd(k.l[2][1]),
                  l22 = _mm512_set1_pd(k.l[2][2]), t2 = _mm512_set1_pd(k.t[2]);
    const __m512d nearW = _mm512_set1_pd(k.nearW), guard = _mm512_set1_pd(k.guard);
    const __m512d scale = _mm512_set1_pd(k.scale), sub = _mm512_set1_pd(256.0);
    const __m512d one = _mm512_set1_pd(1.0);
    const __m256i culled = _mm256_set1_epi32(WarpedVertices::kCulled);
    size_t i = 0;
    for (; i + 8 <= n; i += 8) {
        const __m512d a = _mm512_cvtepi32_pd(
            _mm256_cvtepu16_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(qx + i))));
        const __m512d b = _mm512_cvtepi32_pd(
            _mm256_cvtepu16_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(qy + i))));
        const __m512d c = _mm512_cvtepi32_pd(
            _mm256_cvtepu16_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(qz + i))));
        const __m512d X =
            _mm512_fmadd_pd(l02, c, _mm512_fmadd_pd(l01, b, _mm512_fmadd_pd(l00, a, t0)));
        const __m512d Y =
            _mm512_fmadd_pd(l12, c, _mm512_fmadd_pd(l11, b, _mm512_fmadd_pd(l10, a, t1)));
        const __m512d W =
            _mm512_fmadd_pd(l22, c, _mm512_fmadd_pd(l21, b, _mm512_fmadd_pd(l20, a, t2)));
        const __m512d band = _mm512_mul_pd(guard, W);
        const __m512d negBand = _mm512_sub_pd(_mm512_setzero_pd(), band);
        __mmask8 keep = _mm512_cmp_pd_mask(W, nearW, _CMP_GE_OQ);
        keep &=
            _mm512_cmp_pd_mask(X, band, _CMP_LT_OQ) & _mm512_cmp_pd_mask(X, negBand, _CMP_GT_OQ);
        keep &=
            _mm512_cmp_pd_mask(Y, band, _CMP_LT_OQ) & _mm512_cmp_pd_mask(Y, negBand, _CMP_GT_OQ);
        const __m512d r = _mm512_maskz_div_pd(keep, one, W);
        const __m512d sx = _mm512_roundscale_pd(_mm512_mul_pd(_mm512_mul_pd(X, sub), r),
                                                _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
        const __m512d sy = _mm512_roundscale_pd(_mm512_mul_pd(_mm512_mul_pd(Y, sub), r),
                                                _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
        const __m256i ix = _mm256_mask_blend_epi32(keep, culled, _mm512_cvttpd_epi32(sx));
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(ox + i), ix);
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(oy + i),
                            _mm256_maskz_mov_epi32(keep, _mm512_cvttpd_epi32(sy)));
        _mm256_storeu_ps(oinv + i, _mm512_cvtpd_ps(_mm512_mul_pd(scale, r)));
    }
    warpLanes(k, qx + i, qy + i, qz + i, n - i, ox + i, oy + i, oinv + i);
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

}  // namespace

void FixedPointWarp::warp(const uint16_t* qx, const uint16_t* qy, const uint16_t* qz, size_t n,
                          WarpedVertices& out) const {
    out.resize(n);
    WarpCoefficients k;
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) k.l[r][c] = l_[r][c];
        k.t[r] = t_[r];
    }
    k.nearW = nearW_;
    k.guard = kGuardBand;
    k.scale = std::ldexp(1.0, shift_);
    // Every operation is on doubles holding integers under 2^53 (see the header), so the
    // sums are exact in any evaluation order, fused or not.
    static const bool avx512 = __builtin_cpu_supports("avx512f") &&
                               __builtin_cpu_supports("avx512vl") &&
                               __builtin_cpu_supports("avx512dq");
    if (avx512)
        warpAvx512(k, qx, qy, qz, n, out.x.data(), out.y.data(), out.invDepth.data());
    else
        warpLanes(k, qx, qy, qz, n, out.x.data(), out.y.data(), out.invDepth.data());
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
