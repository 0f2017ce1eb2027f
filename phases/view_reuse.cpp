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

}  // namespace

bool ViewKey::operator==(const ViewKey& o) const {
    return sameCamera(camera, o.camera) && layout == o.layout && shadingRate == o.shadingRate &&
           footprintScale == o.footprintScale && objectFootprint == o.objectFootprint &&
           sameProbe(probe, o.probe) &&
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
        ShadingBatch::input(in, r) = at;
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
