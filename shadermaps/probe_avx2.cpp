#include "shadermaps/probe_avx2.h"

#if defined(__x86_64__) || defined(__i386__)

// Every header the probe code uses comes in before the target switch, so only the code
// below is built for AVX2 and F16C: inline functions of those headers,
// which the linker may merge with other files' copies, stay baseline.
#include <cpuid.h>
#include <immintrin.h>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <span>

#include "geometry/float4.h"
#include "shadermaps/half_float.h"
#include "shadermaps/shader_map.h"

#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2,f16c"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2,f16c")
#endif

// Eight queries a vector (feline_lanes.h): GCC does not define __AVX2__ for a target pragma.
#define MPSHADE_PROBE_LANES 8
#include "shadermaps/probe_batch.h"

namespace mpshade {
namespace {

struct HalfTexelsF16C {
    using Storage = uint16_t;
    static constexpr bool kHalf = true;
    static float load(const uint16_t* p) { return _cvtsh_ss(*p); }
    static Float4 load4(const uint16_t* p) {
        return reinterpret_cast<Float4>(
            _mm_cvtph_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p))));
    }
};

}  // namespace

void probeShaderMapAvx2(const ShaderMap& map, const ProbeOptions& options,
                        std::span<const ProbeQuery> queries, ProbeOutput out,
                        ProbeResidency* residency) {
    if (!map.options().halfPrecision)
        return probeWith<FloatTexels>(map, options, queries, out, residency);
    probeWith<HalfTexelsF16C>(map, options, queries, out, residency);
}

}  // namespace mpshade

#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif

namespace mpshade {

bool probeAvx2Available() {
    // F16C is CPUID leaf 1, ECX bit 29 (not every compiler's __builtin_cpu_supports knows
    // it); AVX2's check includes the system saving the vector state.
    unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
    if (!__get_cpuid(1, &eax, &ebx, &ecx, &edx)) return false;
    return (ecx & (1u << 29)) != 0 && __builtin_cpu_supports("avx2");
}

}  // namespace mpshade

#else

namespace mpshade {

bool probeAvx2Available() {
    return false;
}
void probeShaderMapAvx2(const ShaderMap& map, const ProbeOptions& options,
                        std::span<const ProbeQuery> queries, ProbeOutput out,
                        ProbeResidency* residency) {
    probeShaderMapPortable(map, options, queries, out, residency);
}

}  // namespace mpshade

#endif
