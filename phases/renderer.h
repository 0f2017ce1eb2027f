// renderer.h -- what every renderer offers (the single-phase reference, reference_renderer.h,
// and the multi-phase controller, controller/multiphase_renderer.h): a frame's image or its
// samples for a set of render options, with what the frame cost.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>

#include "phases/frame_stats.h"
#include "phases/image.h"
#include "phases/sample_pattern.h"
#include "scene/scene.h"

namespace mpshade {

// What a frame is rendered at. Width, height and samples per pixel of 0 take the scene's
// setting (resolved()).
struct RenderOptions {
    int width = 0;            // pixels; 0: the scene's setting
    int height = 0;           // pixels; 0: the scene's setting
    int samplesPerPixel = 0;  // 0: the scene's setting
    uint32_t seed = 0;        // sample positions depend only on this (and the pixel)
    int tileSize = 16;        // pixels per side of a parallel work item
    int maxLayers = 16;       // translucent surfaces a camera ray passes through at most
    PixelFilter filter;
    // The multi-phase renderer's quality for this frame (the reference shades every sample
    // with its exact footprint): the shading rate (unset: MultiphaseOptions::shadingRate,
    // else the scene's), and the probe footprint's scale (0: DynamicOptions::footprintScale;
    // 2 reads one mip level coarser than the shading points' footprint asks).
    std::optional<ShadingRate> shadingRate;
    float footprintScale = 0.0f;
    // false: the multi-phase renderer shades this frame afresh even if it sees what the last
    // one did, and keeps nothing for the next (DynamicOptions::reuseBytes): for a frame that
    // measures what shading costs.
    bool reuseStillView = true;

    // These options with every "0: the scene's" replaced by the scene's setting.
    RenderOptions resolved(const RenderSettings& settings) const {
        RenderOptions r = *this;
        if (r.width <= 0) r.width = settings.width;
        if (r.height <= 0) r.height = settings.height;
        if (r.samplesPerPixel <= 0) r.samplesPerPixel = settings.samplesPerPixel;
        return r;
    }
};

// Called from worker threads as work finishes: (work done, work in the frame).
using ProgressFn = std::function<void(int, int)>;

class Renderer {
  public:
    virtual ~Renderer() = default;

    // Renders frame `frame` (time frame / fps) into `image`, whose storage is reused when
    // its size is the frame's (a fresh 640x360 image cost a player 10 ms of page faults per
    // frame); what it cost goes to `stats`.
    virtual void renderFrame(int frame, const RenderOptions& options, FrameStats& stats,
                             Image& image, const ProgressFn& progress = {}) = 0;
    // The per-sample results behind the frame, before filtering: for comparisons that must
    // not blur (coverage tests).
    virtual SampleBuffer renderSamples(int frame, const RenderOptions& options, FrameStats& stats,
                                       const ProgressFn& progress = {}) = 0;

    Image renderFrame(int frame, const RenderOptions& options, FrameStats& stats,
                      const ProgressFn& progress = {}) {
        Image image;
        renderFrame(frame, options, stats, image, progress);
        return image;
    }
};

}  // namespace mpshade
