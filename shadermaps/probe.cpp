#include "shadermaps/probe.h"

#include "shadermaps/probe_batch.h"
#include "shadermaps/probe_f16c.h"

namespace mpshade {

void probeShaderMap(const ShaderMap& map, const ProbeOptions& options,
                    std::span<const ProbeQuery> queries, ProbeOutput out,
                    ProbeResidency* residency) {
    if (!map.options().halfPrecision)
        return probeWith<FloatTexels>(map, options, queries, out, residency);
    // Half storage: the F16C conversions where the processor has them (every x86-64 since
    // 2013), else the portable ones; both convert exactly, so the results are the same.
    static const bool f16c = probeF16CAvailable();
    if (f16c) return probeShaderMapF16C(map, options, queries, out, residency);
    return probeWith<HalfTexels>(map, options, queries, out, residency);
}

void probeShaderMapPortable(const ShaderMap& map, const ProbeOptions& options,
                            std::span<const ProbeQuery> queries, ProbeOutput out,
                            ProbeResidency* residency) {
    if (!map.options().halfPrecision)
        return probeWith<FloatTexels>(map, options, queries, out, residency);
    return probeWith<HalfTexels>(map, options, queries, out, residency);
}

}  // namespace mpshade
