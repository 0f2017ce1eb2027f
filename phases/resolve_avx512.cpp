#include "phases/resolve_builds.h"

#if defined(__x86_64__) || defined(__i386__)

// Every header the band uses comes in before the target switch, so only the band below is
// built for AVX-512: inline functions of those headers, which the linker may merge with
// other files' copies, stay baseline.
#include <immintrin.h>
#include <algorithm>
#include <cstring>

#include "geometry/float4.h"

#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx512f"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx512f")
#endif

#define MPSHADE_RESOLVE_AVX512 1
#include "phases/resolve_rows.h"

namespace mpshade {

void resolveRowsAvx512(const ResolveFrame& frame, int r0, int r1) {
    resolveRowsOf(frame, r0, r1);
}

}  // namespace mpshade

#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif

namespace mpshade {

bool resolveAvx512Available() {
    static const bool available = __builtin_cpu_supports("avx512f");
    return available;
}

}  // namespace mpshade

#else

namespace mpshade {

bool resolveAvx512Available() {
    return false;
}
void resolveRowsAvx512(const ResolveFrame&, int, int) {}

}  // namespace mpshade

#endif
