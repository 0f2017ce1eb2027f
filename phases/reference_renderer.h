// reference_renderer.h -- the single-phase renderer (the patent's FIG. 1 prior art): every
// sample is ray traced against exact geometry and shaded with the whole, unfactored
// shader. It is the judge every multi-phase result is measured against.
#pragma once

#include "phases/renderer.h"
#include "phases/sample_layout_cache.h"
#include "phases/scene_resources.h"

namespace mpshade {

class ReferenceRenderer : public Renderer {
  public:
    explicit ReferenceRenderer(const Scene& scene);

    // Deterministic for given options; safe from several threads at once.
    using Renderer::renderFrame;
    void renderFrame(int frame, const RenderOptions& options, FrameStats& stats, Image& image,
                     const ProgressFn& progress = {}) override;
    SampleBuffer renderSamples(int frame, const RenderOptions& options, FrameStats& stats,
                               const ProgressFn& progress = {}) override;

    const SceneResources& resources() const { return resources_; }

  private:
    const Scene& scene_;
    SceneResources resources_;
    SampleLayoutCache layouts_;
};

}  // namespace mpshade
