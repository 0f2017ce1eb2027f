#include "shadermaps/probe.h"

#include "shadermaps/probe_avx2.h"
#include "shadermaps/probe_batch.h"

namespace mpshade {

void probeShaderMap(const ShaderMap& map, const ProbeOptions& options,
                    std::span<const ProbeQuery> queries, ProbeOutput out,
                    ProbeResidency* residency) {
    // The AVX2 build where the processor runs it (eight queries a vector, half texels by
    // F16C), else the portable one; both give the same bits.
    static const bool avx2 = probeAvx2Available();
    if (avx2) return probeShaderMapAvx2(map, options, queries, out, residency);
    return probeShaderMapPortable(map, options, queries, out, residency);
}

void probeShaderMapPortable(const ShaderMap& map, const ProbeOptions& options,
                            std::span<const ProbeQuery> queries, ProbeOutput out,
                            ProbeResidency* residency) {
    if (!map.options().halfPrecision)
        return probeWith<FloatTexels>(map, options, queries, out, residency);
    return probeWith<HalfTexels>(map, options, queries, out, residency);
}

}  // namespace mpshade
