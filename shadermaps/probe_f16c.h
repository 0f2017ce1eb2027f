// probe_f16c.h -- probes of half-precision shader maps by the F16C conversion
// instructions (vcvtph2ps), chosen at run time; and, for tests and benchmarks, the
// portable build that every processor runs.
#pragma once

#include <span>

#include "shadermaps/probe.h"

namespace mpshade {

// True where this build has the F16C path and the processor runs it.
bool probeF16CAvailable();
// probeShaderMap of a half-precision map by F16C. Only where probeF16CAvailable().
void probeShaderMapF16C(const ShaderMap& map, const ProbeOptions& options,
                        std::span<const ProbeQuery> queries, ProbeOutput out,
                        ProbeResidency* residency);
// probeShaderMap in portable code only, whatever the processor.
void probeShaderMapPortable(const ShaderMap& map, const ProbeOptions& options,
                            std::span<const ProbeQuery> queries, ProbeOutput out,
                            ProbeResidency* residency);

}  // namespace mpshade
