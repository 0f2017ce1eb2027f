// tile_predictor.h -- which shader-map tiles a frame ahead will find missing, predicted by a
// low-resolution dynamic phase (patent claim 11: "a low resolution version of the ...
// frames" tells which tiles will be needed; Fearing 1996's predictive rendering), for a
// player to prefetch in a frame's slack (controller/playback.h).
#pragma once

#include <chrono>
#include <memory>
#include <vector>

#include "controller/multiphase_renderer.h"

namespace mpshade {

class TilePredictor {
  public:
    // renderer: not owned, must outlive the predictor; its representations are drawn.
    explicit TilePredictor(const MultiphaseRenderer& renderer);

    // The tiles frame `frame` will find missing at `options` (its size, samples per pixel, seed),
    // predicted over the objects built: the image 1/divisor each way, one sample a pixel,
    // shading per pixel with footprints scaled to the full image's at the renderer's
    // current rate; its probes fall back, never wait. `seconds` receives its cost. Past
    // `deadline` the prediction is abandoned where it is (abandoned()): rasterization
    // stopped short gives no tiles, shading stopped short the tiles its finished bands
    // found missing; `seconds` then keeps the larger of its time and the cost it held (a whole
    // prediction's, as far as known).
    std::vector<TileRequest> predict(int frame, const RenderOptions& options, int divisor,
                                     double& seconds,
                                     std::chrono::steady_clock::time_point deadline =
                                         std::chrono::steady_clock::time_point::max());
    bool abandoned() const { return abandoned_; }  // the last predict()

  private:
    const MultiphaseRenderer& renderer_;
    DynamicPhase phase_;
    SampleLayoutCache layouts_;
    FrameState state_;  // read by phase_ until the next predict()
    bool abandoned_ = false;
};

}  // namespace mpshade
