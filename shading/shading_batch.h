// shading_batch.h -- storage for one batch of shading points in structure-of-arrays form,
// wired into ShadingInputs and ShadingOutputs. The renderers and the shader-map fill all
// shade through it; it grows when a batch is larger than any before, and otherwise never
// allocates.
#pragma once

#include <vector>

#include "geometry/surface_sample.h"
#include "shading/interpreter.h"

namespace mpshade {

class ShadingBatch {
  public:
    // Input rows, in this order: P, N, Ng, dPdu, dPdv, I (three each), then u, v, s, t.
    enum Row {
        P = 0,
        N = 3,
        Ng = 6,
        dPdu = 9,
        dPdv = 12,
        I = 15,
        U = 18,
        V = 19,
        S = 20,
        T = 21,
        kInputRows = 22
    };

    // Makes room for n points and `channels` n-tuple channels (read or written); what the
    // rows held before is left, not cleared.
    void resize(size_t n, size_t channels);
    size_t size() const { return n_; }

    float* row(int r) { return rows_.data() + static_cast<size_t>(r) * n_; }
    float* channel(size_t c) { return channels_[c]; }
    float* ci(int k) { return out.Ci[k]; }
    float* oi(int k) { return out.Oi[k]; }

    // The pointer of `in` that input row r (Row, below kInputRows) feeds.
    static const float*& input(ShadingInputs& in, int r);

    // Point i: the surface's differential geometry at `at`, seen along unit direction I.
    void setPoint(size_t i, const SurfaceSample& g, const ChartPoint& at, const glm::vec3& I);

    ShadingInputs in;
    ShadingOutputs out;

  private:
    size_t n_ = 0;
    std::vector<float> rows_;  // kInputRows + 6 output rows
    std::vector<float> channelData_;
    std::vector<float*> channels_;
    std::vector<const float*> channelsIn_;
};

}  // namespace mpshade
