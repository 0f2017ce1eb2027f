// multiphase_renderer.h -- multi-phase rendering with the combined intermediate
// representation (patent FIG. 2 and FIG. 4): each object's factored shader and facets.
//
// Static phase (per object, rarely): dice the surface into sub-pixel facets for the
// representative viewpoint (dicing.h), evaluate the static part of the object's factored
// shader at every facet vertex, and keep the n-tuple per vertex -- or, for objects whose
// scene entry asks for "representation": "shadermap" (the patent's separate
// representation, FIG. 5), fill a shader map of the static part and probe it per sample
// with the footprint of the facet's screen-space (u, v) gradient. It runs again for an
// object only when the viewpoint, in the object's own coordinates, leaves the range
// (distance factor and angle of the scene's `range`).
// Dynamic phase (every frame): warp each object's facets in fixed point
// (fixed_point_warp.h), rasterize them to the same sample positions the reference
// renderer uses (facet_rasterizer.h), interpolate the n-tuple and geometry to each sample,
// run the dynamic part, composite front to back and reconstruct pixels with the same
// filter.
#pragma once

#include <memory>
#include <vector>

#include "phases/dicing.h"
#include "phases/facet_mesh.h"
#include "phases/facet_rasterizer.h"
#include "phases/reference_renderer.h"
#include "shadermaps/probe.h"
#include "shading/factoring.h"

namespace mpshade {

struct MultiphaseOptions {
    DicingOptions dicing;
    FactorOptions factor;
    RasterOptions raster;
    ShaderMapOptions
        shaderMap;       // for objects with "representation": "shadermap" (resolution: per object)
    ProbeOptions probe;  // how those objects' maps are probed
};

class MultiphaseRenderer {
  public:
    MultiphaseRenderer(const Scene& scene, const MultiphaseOptions& options = {});
    ~MultiphaseRenderer();

    // Renders frame `frame`, running the static phase first for objects that need it.
    Image renderFrame(int frame, const RenderOptions& options, FrameStats& stats,
                      const ProgressFn& progress = {});
    SampleBuffer renderSamples(int frame, const RenderOptions& options, FrameStats& stats,
                               const ProgressFn& progress = {});

    // The current intermediate representation of object i (null before its static phase).
    const FacetMesh* facets(size_t object) const;
    const FactoredShader& factored(size_t object) const;

  private:
    struct ObjectData;
    void staticPhase(size_t index, const ObjectState& state, const CameraState& camera,
                     const ShadingUniforms& uniforms, FrameStats& stats);

    const Scene& scene_;
    MultiphaseOptions options_;
    SceneResources resources_;
    std::vector<std::unique_ptr<ObjectData>> objects_;
};

}  // namespace mpshade
