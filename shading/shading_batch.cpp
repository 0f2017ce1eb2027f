#include "shading/shading_batch.h"

#include <algorithm>

namespace mpshade {

void ShadingBatch::resize(size_t n, size_t channels) {
    n_ = n;
    rows_.resize((kInputRows + 6) * n);
    channelData_.resize(std::max<size_t>(channels, 1) * n);
    channels_.resize(channels);
    channelsIn_.resize(channels);
    for (int k = 0; k < 3; ++k) {
        in.P[k] = row(P + k);
        in.N[k] = row(N + k);
        in.Ng[k] = row(Ng + k);
        in.dPdu[k] = row(dPdu + k);
        in.dPdv[k] = row(dPdv + k);
        in.I[k] = row(I + k);
        out.Ci[k] = row(kInputRows + k);
        out.Oi[k] = row(kInputRows + 3 + k);
    }
    in.u = row(U), in.v = row(V), in.s = row(S), in.t = row(T);
    for (size_t c = 0; c < channels; ++c)
        channels_[c] = channelData_.data() + c * n, channelsIn_[c] = channels_[c];
    in.channels = channelsIn_.data();
    out.channels = channels_.data();
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
