#include "shading/shading_batch.h"

#include <algorithm>

namespace mpshade {

void ShadingBatch::resize(size_t n, size_t channels) {
    n_ = n;
    // Grown only: a vector shrunk for a small batch would zero its tail again when the
    // next batch is larger (4% of a steady frame's shading instructions, the vase).
    const size_t rowValues = (kInputRows + 6) * n,
                 channelValues = std::max<size_t>(channels, 1) * n;
    if (rows_.size() < rowValues) rows_.resize(rowValues);
    if (channelData_.size() < channelValues) channelData_.resize(channelValues);
    channels_.resize(channels);
    channelsIn_.resize(channels);
    for (int r = 0; r < kInputRows; ++r) input(in, r) = row(r);
    for (int k = 0; k < 3; ++k) {
        out.Ci[k] = row(kInputRows + k);
        out.Oi[k] = row(kInputRows + 3 + k);
    }
    for (size_t c = 0; c < channels; ++c)
        channels_[c] = channelData_.data() + c * n, channelsIn_[c] = channels_[c];
    in.channels = channelsIn_.data();
    out.channels = channels_.data();
}

const float*& ShadingBatch::input(ShadingInputs& in, int r) {
    if (r < N) return in.P[r - P];
    if (r < Ng) return in.N[r - N];
    if (r < dPdu) return in.Ng[r - Ng];
    if (r < dPdv) return in.dPdu[r - dPdu];
    if (r < I) return in.dPdv[r - dPdv];
    if (r < U) return in.I[r - I];
    if (r == U) return in.u;
    if (r == V) return in.v;
    if (r == S) return in.s;
    return in.t;
}

void ShadingBatch::setPoint(size_t i, const SurfaceSample& g, const ChartPoint& at,
                            const glm::vec3& dir) {
    for (int k = 0; k < 3; ++k) {
        row(P + k)[i] = g.P[k];
        row(N + k)[i] = g.N[k];
        row(Ng + k)[i] = g.Ng[k];
        row(dPdu + k)[i] = g.dPdu[k];
        row(dPdv + k)[i] = g.dPdv[k];
        row(I + k)[i] = dir[k];
    }
    row(U)[i] = at.u;
    row(V)[i] = at.v;
    row(S)[i] = g.s;
    row(T)[i] = g.t;
}

}  // namespace mpshade
