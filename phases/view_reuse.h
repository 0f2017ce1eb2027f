// view_reuse.h -- what the dynamic phase keeps of a frame for the next one that sees the
// scene exactly as it did.
//
// The transform-sample-interpolate step has a static part too (patent col. 4: a factoring of
// it as of the shader): a frame whose camera, object placements, representations, sample
// layout and probe settings all equal the last frame's has the same visibility, the same
// shading points and the same inputs to every point's dynamic shader -- position, view
// direction, geometry and the probed n-tuple -- and differs only in the shader's uniforms
// (time, the lights, animated parameters). A still camera over still objects under a moving
// light (Guenter, Knoblock and Ruf's best case) is such a sequence. Such a frame skips
// the warp, rasterization, point building, facet intersection, interpolation and probes,
// and runs the dynamic shader on the inputs the last frame kept: the same bits as shading
// afresh, since the same inputs go through the same kernel.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/mat4x4.hpp>

#include "scene/scene_state.h"
#include "shadermaps/probe.h"
#include "shading/shading_batch.h"

namespace mpshade {

class SampleLayout;

// Everything a frame's shading inputs depend on but the shader's uniforms.
struct ViewKey {
    CameraState camera;
    const SampleLayout* layout = nullptr;  // layouts are shared and immutable: by identity
    int shadingRate = 0;
    float footprintScale = 0.0f;
    std::vector<float> objectFootprint;  // DynamicOptions::objectFootprint
    ProbeOptions probe;
    int bandRows = 0;
    bool wholePixelShortcut = false;
    std::vector<uint64_t> serials;      // per object: its representation's serial, 0 if not drawn
    std::vector<glm::mat4> placements;  // per object: object to world

    bool operator==(const ViewKey& o) const;
};

// Per object: the batch rows its points' inputs take (shadingInputRows) and its channel count.
struct InputLayout {
    std::vector<std::vector<int>> rows;
    std::vector<size_t> channels;
};

// One band's kept inputs: for each batch of points, in the order the band shades them, each
// kept row's n values and then each channel's. Valid only once the whole band was recorded
// from a pass that shaded every point (no tile missing, no coarser level read instead).
class BandInputs {
  public:
    bool valid() const { return valid_; }
    size_t bytes() const { return values_.capacity() * sizeof(float); }
    // Starts recording (the last recording is dropped; its storage reused).
    void start() {
        values_.clear();
        valid_ = false;
    }
    void append(ShadingBatch& batch, std::span<const int> rows, size_t channels, size_t n);
    void finish() { valid_ = true; }
    void invalidate() { valid_ = false; }
    void release() {
        values_ = {};
        valid_ = false;
    }
    // Points `in` at the next batch of n points' kept values, from `cursor` on, which it
    // advances: each kept row's pointer, and the n-tuple's through `channels` (resized to
    // `channelCount`). Nothing is copied; the pointers hold until the next start().
    void restore(ShadingInputs& in, std::vector<const float*>& channels, std::span<const int> rows,
                 size_t channelCount, size_t n, size_t& cursor) const;

  private:
    std::vector<float> values_;
    bool valid_ = false;
};

}  // namespace mpshade
