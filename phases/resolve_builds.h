// resolve_builds.h -- SampleLayout::resolve's bands (resolve_rows.h) built for wider
// instruction sets, chosen at run time where the processor has them: the same bits as the
// baseline build (resolve_avx512.cpp, resolve_avx2.cpp).
#pragma once

#include "phases/resolve_frame.h"

namespace mpshade {

// True where this build has the AVX-512 resolve and the processor runs it.
bool resolveAvx512Available();
// Output rows [r0, r1) of `frame` (resolve_rows.h). Only where resolveAvx512Available().
void resolveRowsAvx512(const ResolveFrame& frame, int r0, int r1);

// The same for AVX2.
bool resolveAvx2Available();
void resolveRowsAvx2(const ResolveFrame& frame, int r0, int r1);

}  // namespace mpshade
