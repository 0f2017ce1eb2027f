// probe_avx2.h -- probes built for AVX2 (and the F16C conversions of half-precision maps),
// chosen at run time: eight queries a vector in feline_lanes.h, and binary16 texels
// converted by vcvtph2ps. Without fused multiply-adds, so every build's probes give the
// same bits. For tests and benchmarks, the portable build that every processor runs.
#pragma once

#include <span>

#include "shadermaps/probe.h"

namespace mpshade {

// True where this build has the AVX2 path and the processor runs it (AVX2 and F16C).
bool probeAvx2Available();

// probeShaderMap by the AVX2 build. Only where probeAvx2Available().
void probeShaderMapAvx2(const ShaderMap& map, const ProbeOptions& options,
                        std::span<const ProbeQuery> queries, ProbeOutput out,
                        ProbeResidency* residency);

// probeShaderMap in portable code only, whatever the processor.
void probeShaderMapPortable(const ShaderMap& map, const ProbeOptions& options,
                            std::span<const ProbeQuery> queries, ProbeOutput out,
                            ProbeResidency* residency);

}  // namespace mpshade
