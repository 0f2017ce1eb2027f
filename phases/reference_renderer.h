// reference_renderer.h -- the single-phase renderer (the patent's FIG. 1 prior art): every
// sample is ray traced against exact geometry and shaded with the whole, unfactored
// shader. It is the judge every multi-phase result is measured against.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>

#include "phases/frame_stats.h"
#include "phases/image.h"
#include "phases/sample_pattern.h"
#include "phases/scene_resources.h"

namespace mpshade {

struct RenderOptions {
    int width = 0;            // 0: the scene's setting
    int height = 0;           // 0: the scene's setting
    int samplesPerPixel = 0;  // 0: the scene's setting
    uint32_t seed = 0;        // sample positions depend only on this (and the pixel)
    int tileSize = 16;        // pixels per side of a parallel work item
    int maxLayers = 16;       // translucent surfaces a camera ray passes through at most
    PixelFilter filter;
};

// Called from worker threads as tiles finish: (tiles done, tiles in the frame).
using ProgressFn = std::function<void(int, int)>;

class ReferenceRenderer {
  public:
    explicit ReferenceRenderer(const Scene& scene);

    // Renders frame `frame` (time frame / fps). Deterministic for given options.
    Image renderFrame(int frame, const RenderOptions& options, FrameStats& stats,
                      const ProgressFn& progress = {}) const;

    // The per-sample results behind the last image, before filtering; for comparisons
    // that must not blur (coverage tests).
    SampleBuffer renderSamples(int frame, const RenderOptions& options, FrameStats& stats,
                               const ProgressFn& progress = {}) const;

    const SceneResources& resources() const { return resources_; }

  private:
    std::shared_ptr<const SampleLayout> layoutFor(int width, int height, int spp,
                                                  const RenderOptions& options) const;

    const Scene& scene_;
    SceneResources resources_;
    mutable std::mutex layoutMutex_;
    mutable std::shared_ptr<const SampleLayout> layout_;  // reused while the size stays
};

}  // namespace mpshade
