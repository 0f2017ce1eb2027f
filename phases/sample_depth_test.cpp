#include "phases/sample_depth_test.h"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace mpshade {

namespace {

// The compiled loop: plain arithmetic on doubles that GCC vectorizes, cloned for AVX-512,
// AVX2 and the baseline. Fastest on long rows (facets wider than 16 pixels at 4 spp: a floor
// covering whole tiles).
__attribute__((target_clones("avx512f", "avx2", "default"))) uint32_t depthTestCompiled(
    const SampleRows& r, const DepthTestFacet& f) {
    const FacetEdges& s = *f.edges;
    const double c0 = s.c[0], c1 = s.c[1], c2 = s.c[2];
    const double a0 = s.a[0], a1 = s.a[1], a2 = s.a[2];
    const double b0 = s.b[0], b1 = s.b[1], b2 = s.b[2];
    const double zc = s.zc, zx = s.zx, zy = s.zy;
    const int32_t ox = f.ox, oy = f.oy;
    const uint32_t o = f.object, id = f.facet;
    const int32_t* fx = r.fx;
    const int32_t* fy = r.fy;
    float* inv = r.invDepth;
    uint32_t* object = r.object;
    uint32_t* facet = r.facet;
    const size_t n = r.n;
    uint32_t inside = 0;
    for (size_t row = 0; row < r.rows; ++row, fx += r.stride, fy += r.stride, inv += r.stride,
                object += r.stride, facet += r.stride) {
        if (f.testEdges) {
            for (size_t i = 0; i < n; ++i) {
                const double lx = fx[i] - ox, ly = fy[i] - oy;
                const bool in = (c0 + a0 * lx + b0 * ly > 0.0) & (c1 + a1 * lx + b1 * ly > 0.0) &
                                (c2 + a2 * lx + b2 * ly > 0.0);
                const float z = static_cast<float>(zc + zx * lx + zy * ly);
                const bool hit = in & (z > inv[i]);
                inside += in;
                inv[i] = hit ? z : inv[i];
                object[i] = hit ? o : object[i];
                facet[i] = hit ? id : facet[i];
            }
        } else {
            for (size_t i = 0; i < n; ++i) {
                const double lx = fx[i] - ox, ly = fy[i] - oy;
                const float z = static_cast<float>(zc + zx * lx + zy * ly);
                const bool hit = z > inv[i];
                inv[i] = hit ? z : inv[i];
                object[i] = hit ? o : object[i];
                facet[i] = hit ? id : facet[i];
            }
            inside += static_cast<uint32_t>(n);
        }
    }
    return inside;
}

#if defined(__x86_64__)
// GCC 12's conversion intrinsics start from an undefined vector, which
// -Wmaybe-uninitialized reports inside the header.
#pragma GCC diagnostic push
#if !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

// A facet's edge functions and depth plane in four double lanes.
struct EdgeLanes4 {
    __m256d c0, c1, c2, a0, a1, a2, b0, b1, b2, zc, zx, zy;
    __m128i ox, oy;
    bool testEdges;
};

// Lanes of 1 / depth (*z) and the edge test (a lane mask of four floats) for samples at
// (x, y), in 1/256 pixels.
__attribute__((target("avx2"), always_inline)) inline __m128 testLanes4(const EdgeLanes4& e,
                                                                        __m128i x, __m128i y,
                                                                        __m128* z) {
    const __m256d lx = _mm256_cvtepi32_pd(_mm_sub_epi32(x, e.ox));
    const __m256d ly = _mm256_cvtepi32_pd(_mm_sub_epi32(y, e.oy));
    *z = _mm256_cvtpd_ps(
        _mm256_add_pd(_mm256_add_pd(e.zc, _mm256_mul_pd(e.zx, lx)), _mm256_mul_pd(e.zy, ly)));
    if (!e.testEdges) return _mm_castsi128_ps(_mm_set1_epi32(-1));
    const __m256d zero = _mm256_setzero_pd();
    const __m256d e0 =
        _mm256_add_pd(_mm256_add_pd(e.c0, _mm256_mul_pd(e.a0, lx)), _mm256_mul_pd(e.b0, ly));
    const __m256d e1 =
        _mm256_add_pd(_mm256_add_pd(e.c1, _mm256_mul_pd(e.a1, lx)), _mm256_mul_pd(e.b1, ly));
    const __m256d e2 =
        _mm256_add_pd(_mm256_add_pd(e.c2, _mm256_mul_pd(e.a2, lx)), _mm256_mul_pd(e.b2, ly));
    const __m256d in = _mm256_and_pd(
        _mm256_and_pd(_mm256_cmp_pd(e0, zero, _CMP_GT_OQ), _mm256_cmp_pd(e1, zero, _CMP_GT_OQ)),
        _mm256_cmp_pd(e2, zero, _CMP_GT_OQ));
    // The even 32-bit halves of the four 64-bit lane masks.
    return _mm256_castps256_ps128(
        _mm256_permutevar8x32_ps(_mm256_castpd_ps(in), _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6)));
}

// By hand in AVX2, four samples a vector in double lanes. The compiled AVX2 loop kept its
// broadcast constants partly on the stack and reloaded them every four samples, and ran a
// scalar tail; rows of a small facet are 4-16 samples.
__attribute__((target("avx2"))) uint32_t depthTestAvx2(const SampleRows& r,
                                                       const DepthTestFacet& f) {
    const FacetEdges& s = *f.edges;
    const EdgeLanes4 e{_mm256_set1_pd(s.c[0]), _mm256_set1_pd(s.c[1]), _mm256_set1_pd(s.c[2]),
                       _mm256_set1_pd(s.a[0]), _mm256_set1_pd(s.a[1]), _mm256_set1_pd(s.a[2]),
                       _mm256_set1_pd(s.b[0]), _mm256_set1_pd(s.b[1]), _mm256_set1_pd(s.b[2]),
                       _mm256_set1_pd(s.zc),   _mm256_set1_pd(s.zx),   _mm256_set1_pd(s.zy),
                       _mm_set1_epi32(f.ox),   _mm_set1_epi32(f.oy),   f.testEdges};
    const __m128i o4 = _mm_set1_epi32(static_cast<int>(f.object)),
                  f4 = _mm_set1_epi32(static_cast<int>(f.facet));
    uint32_t inside = 0;
    for (size_t row = 0; row < r.rows; ++row) {
        const size_t at = row * r.stride;
        const int32_t* fx = r.fx + at;
        const int32_t* fy = r.fy + at;
        float* inv = r.invDepth + at;
        auto* object = reinterpret_cast<__m128i*>(r.object + at);
        auto* facet = reinterpret_cast<__m128i*>(r.facet + at);
        size_t i = 0;
        for (; i + 4 <= r.n; i += 4) {
            __m128 z;
            const __m128 in =
                testLanes4(e, _mm_loadu_si128(reinterpret_cast<const __m128i*>(fx + i)),
                           _mm_loadu_si128(reinterpret_cast<const __m128i*>(fy + i)), &z);
            const __m128 old = _mm_loadu_ps(inv + i);
            const __m128 hit = _mm_and_ps(in, _mm_cmpgt_ps(z, old));
            const __m128i h = _mm_castps_si128(hit);
            _mm_storeu_ps(inv + i, _mm_blendv_ps(old, z, hit));
            const size_t k = i / 4;
            _mm_storeu_si128(object + k, _mm_blendv_epi8(_mm_loadu_si128(object + k), o4, h));
            _mm_storeu_si128(facet + k, _mm_blendv_epi8(_mm_loadu_si128(facet + k), f4, h));
            inside += static_cast<uint32_t>(__builtin_popcount(_mm_movemask_ps(in)));
        }
        // The last 1-3 samples (at 1 or 2 spp) one at a time, as the compiled loop does
        // them: lanes past the row may be another tile's, and masked loads and stores
        // (vmaskmov, microcoded on AMD processors) had made a row of one sample 2.4x slower
        // than the compiled loop's scalar tail; a copy into a vector, 3.2x.
        for (; i < r.n; ++i) {
            const double lx = fx[i] - f.ox, ly = fy[i] - f.oy;
            const bool in = !f.testEdges || ((s.c[0] + s.a[0] * lx + s.b[0] * ly > 0.0) &
                                             (s.c[1] + s.a[1] * lx + s.b[1] * ly > 0.0) &
                                             (s.c[2] + s.a[2] * lx + s.b[2] * ly > 0.0));
            const float z = static_cast<float>(s.zc + s.zx * lx + s.zy * ly);
            inside += in;
            if (in && z > inv[i])
                inv[i] = z, r.object[at + i] = f.object, r.facet[at + i] = f.facet;
        }
    }
    return inside;
}

// By hand in AVX-512: a row's samples eight at a time in double lanes, the last eight
// masked rather than a scalar tail, the count by a population count of masks. Facets a
// pixel or two across give rows of 4-16 samples, where GCC's vectorized loop spent most of
// its time on its tail and on summing its count lane by lane (42% of rasterizing 1-pixel
// facets went to the sample test).
__attribute__((target("avx512f,avx512vl"))) uint32_t depthTestAvx512(const SampleRows& r,
                                                                     const DepthTestFacet& f) {
    const FacetEdges& s = *f.edges;
    const __m512d c0 = _mm512_set1_pd(s.c[0]), c1 = _mm512_set1_pd(s.c[1]),
                  c2 = _mm512_set1_pd(s.c[2]);
    const __m512d a0 = _mm512_set1_pd(s.a[0]), a1 = _mm512_set1_pd(s.a[1]),
                  a2 = _mm512_set1_pd(s.a[2]);
    const __m512d b0 = _mm512_set1_pd(s.b[0]), b1 = _mm512_set1_pd(s.b[1]),
                  b2 = _mm512_set1_pd(s.b[2]);
    const __m512d zc = _mm512_set1_pd(s.zc), zx = _mm512_set1_pd(s.zx), zy = _mm512_set1_pd(s.zy);
    const __m512d zero = _mm512_setzero_pd();
    const __m256i ox8 = _mm256_set1_epi32(f.ox), oy8 = _mm256_set1_epi32(f.oy);
    const __m256i o8 = _mm256_set1_epi32(static_cast<int>(f.object)),
                  f8 = _mm256_set1_epi32(static_cast<int>(f.facet));
    uint32_t inside = 0;
    for (size_t row = 0; row < r.rows; ++row) {
        const size_t at = row * r.stride;
        const int32_t* fx = r.fx + at;
        const int32_t* fy = r.fy + at;
        float* inv = r.invDepth + at;
        uint32_t* object = r.object + at;
        uint32_t* facet = r.facet + at;
        for (size_t i = 0; i < r.n; i += 8) {
            const size_t left = r.n - i;
            const __mmask8 lanes =
                left >= 8 ? __mmask8(0xFF) : static_cast<__mmask8>((1u << left) - 1u);
            const __m512d lx =
                _mm512_cvtepi32_pd(_mm256_sub_epi32(_mm256_maskz_loadu_epi32(lanes, fx + i), ox8));
            const __m512d ly =
                _mm512_cvtepi32_pd(_mm256_sub_epi32(_mm256_maskz_loadu_epi32(lanes, fy + i), oy8));
            __mmask8 in = lanes;
            if (f.testEdges) {
                const __m512d e0 =
                    _mm512_add_pd(_mm512_add_pd(c0, _mm512_mul_pd(a0, lx)), _mm512_mul_pd(b0, ly));
                const __m512d e1 =
                    _mm512_add_pd(_mm512_add_pd(c1, _mm512_mul_pd(a1, lx)), _mm512_mul_pd(b1, ly));
                const __m512d e2 =
                    _mm512_add_pd(_mm512_add_pd(c2, _mm512_mul_pd(a2, lx)), _mm512_mul_pd(b2, ly));
                in = _mm512_mask_cmp_pd_mask(in, e0, zero, _CMP_GT_OQ);
                in = _mm512_mask_cmp_pd_mask(in, e1, zero, _CMP_GT_OQ);
                in = _mm512_mask_cmp_pd_mask(in, e2, zero, _CMP_GT_OQ);
            }
            const __m256 z = _mm512_cvtpd_ps(
                _mm512_add_pd(_mm512_add_pd(zc, _mm512_mul_pd(zx, lx)), _mm512_mul_pd(zy, ly)));
            const __mmask8 hit =
                _mm256_mask_cmp_ps_mask(in, z, _mm256_maskz_loadu_ps(in, inv + i), _CMP_GT_OQ);
            _mm256_mask_storeu_ps(inv + i, hit, z);
            _mm256_mask_storeu_epi32(object + i, hit, o8);
            _mm256_mask_storeu_epi32(facet + i, hit, f8);
            inside += static_cast<uint32_t>(__builtin_popcount(in));
        }
    }
    return inside;
}
#pragma GCC diagnostic pop
#endif

// Rows of up to this many samples go to a kernel by hand; longer ones (facets wider than 16
// pixels at 4 spp) to the compiled loop, which is as fast there. See docs/multiphase.md.
constexpr size_t kShortRow = 64;

}  // namespace

bool depthTestKernelAvailable(DepthTestKernel kernel) {
#if defined(__x86_64__)
    static const bool avx2 = __builtin_cpu_supports("avx2");
    static const bool avx512 =
        __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl");
    switch (kernel) {
        case DepthTestKernel::Compiled:
            return true;
        case DepthTestKernel::Avx2:
            return avx2;
        case DepthTestKernel::Avx512:
            return avx512;
    }
    return false;
#else
    return kernel == DepthTestKernel::Compiled;
#endif
}

uint32_t depthTestRowsWith(DepthTestKernel kernel, const SampleRows& rows,
                           const DepthTestFacet& facet) {
#if defined(__x86_64__)
    if (kernel == DepthTestKernel::Avx512) return depthTestAvx512(rows, facet);
    if (kernel == DepthTestKernel::Avx2) return depthTestAvx2(rows, facet);
#endif
    return depthTestCompiled(rows, facet);
}

uint32_t depthTestRows(const SampleRows& rows, const DepthTestFacet& facet) {
    static const DepthTestKernel shortRows =
        depthTestKernelAvailable(DepthTestKernel::Avx512) ? DepthTestKernel::Avx512
        : depthTestKernelAvailable(DepthTestKernel::Avx2) ? DepthTestKernel::Avx2
                                                          : DepthTestKernel::Compiled;
    return depthTestRowsWith(rows.n <= kShortRow ? shortRows : DepthTestKernel::Compiled, rows,
                             facet);
}

}  // namespace mpshade
