#include "phases/view_reuse.h"

#include <algorithm>
#include <cstring>

namespace mpshade {
namespace {

bool sameCamera(const CameraState& a, const CameraState& b) {
    return a.eye == b.eye && a.forward == b.forward && a.right == b.right && a.up == b.up &&
           a.tanHalfFovY == b.tanHalfFovY && a.aspect == b.aspect && a.zNear == b.zNear &&
           a.zFar == b.zFar && a.width == b.width && a.height == b.height;
}

bool sameProbe(const ProbeOptions& a, const ProbeOptions& b) {
    return a.filter == b.filter && a.maxAnisotropy == b.maxAnisotropy &&
           a.levelBlend == b.levelBlend && a.tapsPerRatio == b.tapsPerRatio && a.cap == b.cap &&
           a.levelAnisotropy == b.levelAnisotropy;
}

// The pointer of ShadingInputs that batch row r (ShadingBatch::Row) feeds.
const float*& inputRow(ShadingInputs& in, int r) {
    if (r < ShadingBatch::N) return in.P[r - ShadingBatch::P];
    if (r < ShadingBatch::Ng) return in.N[r - ShadingBatch::N];
    if (r < ShadingBatch::dPdu) return in.Ng[r - ShadingBatch::Ng];
    if (r < ShadingBatch::dPdv) return in.dPdu[r - ShadingBatch::dPdu];
    if (r < ShadingBatch::I) return in.dPdv[r - ShadingBatch::dPdv];
    if (r < ShadingBatch::U) return in.I[r - ShadingBatch::I];
    if (r == ShadingBatch::U) return in.u;
    if (r == ShadingBatch::V) return in.v;
    if (r == ShadingBatch::S) return in.s;
    return in.t;
}

}  // namespace

bool ViewKey::operator==(const ViewKey& o) const {
    return sameCamera(camera, o.camera) && layout == o.layout && shadingRate == o.shadingRate &&
           footprintScale == o.footprintScale && sameProbe(probe, o.probe) &&
           bandRows == o.bandRows && wholePixelShortcut == o.wholePixelShortcut &&
           serials == o.serials && placements == o.placements;
}

void BandInputs::append(ShadingBatch& batch, std::span<const int> rows, size_t channels, size_t n) {
    const size_t at = values_.size();
    values_.resize(at + (rows.size() + channels) * n);
    float* out = values_.data() + at;
    for (int r : rows) {
        std::memcpy(out, batch.row(r), n * sizeof(float));
        out += n;
    }
    for (size_t c = 0; c < channels; ++c) {
        std::memcpy(out, batch.channel(c), n * sizeof(float));
        out += n;
    }
}

void BandInputs::restore(ShadingInputs& in, std::vector<const float*>& channels,
                         std::span<const int> rows, size_t channelCount, size_t n,
                         size_t& cursor) const {
    const float* at = values_.data() + cursor;
    for (int r : rows) {
        inputRow(in, r) = at;
        at += n;
    }
    channels.resize(channelCount);
    for (size_t c = 0; c < channelCount; ++c) {
        channels[c] = at;
        at += n;
    }
    in.channels = channels.data();
    cursor += (rows.size() + channelCount) * n;
}

}  // namespace mpshade
