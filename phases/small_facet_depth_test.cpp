#include "phases/small_facet_depth_test.h"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace mpshade {

// The edges in int32 (exact within the box: see the header). A tenth of the instructions of
// rasterizing facets a pixel across had gone to the large facets' 64-bit edges.
SmallFacetEdges smallFacetEdges(const int32_t x[3], const int32_t y[3], const float w[3],
                                int32_t ox, int32_t oy) {
    SmallFacetEdges s;
    setUpFacetEdges<int32_t>(x, y, w, ox, oy, s);
    s.ox = ox, s.oy = oy;
    return s;
}

namespace {

__attribute__((target_clones("avx2", "default"))) uint32_t smallFacetCompiled(
    const SampleRows& r, const SmallFacetEdges& s, uint32_t o, uint32_t id) {
    uint32_t inside = 0;
    for (size_t row = 0; row < r.rows; ++row) {
        const size_t at = row * r.stride;
        const int32_t* fx = r.fx + at;
        const int32_t* fy = r.fy + at;
        float* inv = r.invDepth + at;
        uint32_t* object = r.object + at;
        uint32_t* facet = r.facet + at;
        for (size_t i = 0; i < r.n; ++i) {
            const float lx = static_cast<float>(fx[i] - s.ox),
                        ly = static_cast<float>(fy[i] - s.oy);
            const bool in = smallFacetInside(s, lx, ly);
            const float z = smallFacetDepth(s, lx, ly);
            const bool hit = in & (z > inv[i]);
            inside += in;
            inv[i] = hit ? z : inv[i];
            object[i] = hit ? o : object[i];
            facet[i] = hit ? id : facet[i];
        }
    }
    return inside;
}

#if defined(__x86_64__)
// Eight samples a vector, then four, then one at a time: rows at 4 spp are whole pixels of
// four samples, so the scalar tail is only for 1 and 2 spp. The edges fused (exact either
// way), the plane not.
__attribute__((target("avx2,fma"))) uint32_t smallFacetAvx2(const SampleRows& r,
                                                            const SmallFacetEdges& s, uint32_t o,
                                                            uint32_t id) {
    const __m256 c0 = _mm256_set1_ps(s.c[0]), c1 = _mm256_set1_ps(s.c[1]),
                 c2 = _mm256_set1_ps(s.c[2]);
    const __m256 a0 = _mm256_set1_ps(s.a[0]), a1 = _mm256_set1_ps(s.a[1]),
                 a2 = _mm256_set1_ps(s.a[2]);
    const __m256 b0 = _mm256_set1_ps(s.b[0]), b1 = _mm256_set1_ps(s.b[1]),
                 b2 = _mm256_set1_ps(s.b[2]);
    const __m256 zc = _mm256_set1_ps(s.zc), zx = _mm256_set1_ps(s.zx), zy = _mm256_set1_ps(s.zy);
    const __m256 zero = _mm256_setzero_ps();
    const __m256i ox = _mm256_set1_epi32(s.ox), oy = _mm256_set1_epi32(s.oy);
    const __m256i o8 = _mm256_set1_epi32(static_cast<int>(o)),
                  f8 = _mm256_set1_epi32(static_cast<int>(id));
    uint32_t inside = 0;
    for (size_t row = 0; row < r.rows; ++row) {
        const size_t at = row * r.stride;
        const int32_t* fx = r.fx + at;
        const int32_t* fy = r.fy + at;
        float* inv = r.invDepth + at;
        uint32_t* object = r.object + at;
        uint32_t* facet = r.facet + at;
        size_t i = 0;
        // Lanes past the row are another tile's or another row's: eight lanes only while
        // the row has eight samples left, then four in half vectors.
        for (; i + 8 <= r.n; i += 8) {
            const __m256 lx = _mm256_cvtepi32_ps(
                _mm256_sub_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(fx + i)), ox));
            const __m256 ly = _mm256_cvtepi32_ps(
                _mm256_sub_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(fy + i)), oy));
            const __m256 e0 = _mm256_fmadd_ps(b0, ly, _mm256_fmadd_ps(a0, lx, c0));
            const __m256 e1 = _mm256_fmadd_ps(b1, ly, _mm256_fmadd_ps(a1, lx, c1));
            const __m256 e2 = _mm256_fmadd_ps(b2, ly, _mm256_fmadd_ps(a2, lx, c2));
            const __m256 in =
                _mm256_cmp_ps(_mm256_min_ps(e0, _mm256_min_ps(e1, e2)), zero, _CMP_GT_OQ);
            const __m256 z =
                _mm256_add_ps(_mm256_add_ps(zc, _mm256_mul_ps(zx, lx)), _mm256_mul_ps(zy, ly));
            const __m256 old = _mm256_loadu_ps(inv + i);
            const __m256 hit = _mm256_and_ps(in, _mm256_cmp_ps(z, old, _CMP_GT_OQ));
            _mm256_storeu_ps(inv + i, _mm256_blendv_ps(old, z, hit));
            const __m256i h = _mm256_castps_si256(hit);
            auto* ob = reinterpret_cast<__m256i*>(object + i);
            auto* fa = reinterpret_cast<__m256i*>(facet + i);
            _mm256_storeu_si256(ob, _mm256_blendv_epi8(_mm256_loadu_si256(ob), o8, h));
            _mm256_storeu_si256(fa, _mm256_blendv_epi8(_mm256_loadu_si256(fa), f8, h));
            inside += static_cast<uint32_t>(__builtin_popcount(_mm256_movemask_ps(in)));
        }
        if (i + 4 <= r.n) {
            const __m128 lx = _mm_cvtepi32_ps(
                _mm_sub_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(fx + i)),
                              _mm256_castsi256_si128(ox)));
            const __m128 ly = _mm_cvtepi32_ps(
                _mm_sub_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(fy + i)),
                              _mm256_castsi256_si128(oy)));
            const __m128 e0 = _mm_fmadd_ps(
                _mm256_castps256_ps128(b0), ly,
                _mm_fmadd_ps(_mm256_castps256_ps128(a0), lx, _mm256_castps256_ps128(c0)));
            const __m128 e1 = _mm_fmadd_ps(
                _mm256_castps256_ps128(b1), ly,
                _mm_fmadd_ps(_mm256_castps256_ps128(a1), lx, _mm256_castps256_ps128(c1)));
            const __m128 e2 = _mm_fmadd_ps(
                _mm256_castps256_ps128(b2), ly,
                _mm_fmadd_ps(_mm256_castps256_ps128(a2), lx, _mm256_castps256_ps128(c2)));
            const __m128 in = _mm_cmpgt_ps(_mm_min_ps(e0, _mm_min_ps(e1, e2)), _mm_setzero_ps());
            const __m128 z = _mm_add_ps(
                _mm_add_ps(_mm256_castps256_ps128(zc), _mm_mul_ps(_mm256_castps256_ps128(zx), lx)),
                _mm_mul_ps(_mm256_castps256_ps128(zy), ly));
            const __m128 old = _mm_loadu_ps(inv + i);
            const __m128 hit = _mm_and_ps(in, _mm_cmpgt_ps(z, old));
            _mm_storeu_ps(inv + i, _mm_blendv_ps(old, z, hit));
            const __m128i h = _mm_castps_si128(hit);
            auto* ob = reinterpret_cast<__m128i*>(object + i);
            auto* fa = reinterpret_cast<__m128i*>(facet + i);
            _mm_storeu_si128(ob,
                             _mm_blendv_epi8(_mm_loadu_si128(ob), _mm256_castsi256_si128(o8), h));
            _mm_storeu_si128(fa,
                             _mm_blendv_epi8(_mm_loadu_si128(fa), _mm256_castsi256_si128(f8), h));
            inside += static_cast<uint32_t>(__builtin_popcount(_mm_movemask_ps(in)));
            i += 4;
        }
        for (; i < r.n; ++i) {
            const float lx = static_cast<float>(fx[i] - s.ox),
                        ly = static_cast<float>(fy[i] - s.oy);
            const bool in = smallFacetInside(s, lx, ly);
            const float z = smallFacetDepth(s, lx, ly);
            inside += in;
            if (in && z > inv[i]) inv[i] = z, object[i] = o, facet[i] = id;
        }
    }
    return inside;
}
#endif

}  // namespace

bool smallFacetKernelAvailable(SmallFacetKernel kernel) {
#if defined(__x86_64__)
    static const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
    return kernel == SmallFacetKernel::Compiled || avx2;
#else
    return kernel == SmallFacetKernel::Compiled;
#endif
}

uint32_t smallFacetDepthTestWith(SmallFacetKernel kernel, const SampleRows& rows,
                                 const SmallFacetEdges& edges, uint32_t object, uint32_t facet) {
#if defined(__x86_64__)
    if (kernel == SmallFacetKernel::Avx2) return smallFacetAvx2(rows, edges, object, facet);
#endif
    return smallFacetCompiled(rows, edges, object, facet);
}

uint32_t smallFacetDepthTest(const SampleRows& rows, const SmallFacetEdges& edges, uint32_t object,
                             uint32_t facet) {
    static const SmallFacetKernel best = smallFacetKernelAvailable(SmallFacetKernel::Avx2)
                                             ? SmallFacetKernel::Avx2
                                             : SmallFacetKernel::Compiled;
    return smallFacetDepthTestWith(best, rows, edges, object, facet);
}

}  // namespace mpshade
