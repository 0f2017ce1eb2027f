// dynamic_frame.h -- a scene's objects built for frame 0 and what a dynamic phase over them
// needs, for the tests of the dynamic phase.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "phases/dynamic_phase.h"
#include "phases/static_phase.h"
#include "scene/scene.h"

namespace mpshade::test {

constexpr int kWidth = 16, kHeight = 12, kSpp = 4;

// A scene's objects built for frame 0 (each as `kind`), and a dynamic phase over them.
struct Frame {
    Scene scene;
    SceneResources resources{scene, SceneResources::RayScenes::ForOcclusion};
    StaticPhase statics{scene, resources};
    FrameState state;
    std::vector<std::unique_ptr<ObjectRepresentation>> reps;
    std::vector<const ObjectRepresentation*> drawn;
    std::shared_ptr<const SampleLayout> layout;

    Frame(const std::string& path, Representation kind, int width = kWidth, int height = kHeight)
        : scene(loadScene(path)) {
        state = frameStateAt(resources, 0, width, height, kSpp);
        for (size_t i = 0; i < scene.objects.size(); ++i) {
            StaticCosts costs;
            reps.push_back(statics.build(i, kind, state.objects[i], state.camera, state.uniforms[i],
                                         nullptr, costs));
            drawn.push_back(reps.back().get());
        }
        layout = std::make_shared<const SampleLayout>(width, height, kSpp, 7u);
    }
    DynamicOptions options(ShadingRate rate) const {
        DynamicOptions o;
        o.shadingRate = rate;
        return o;
    }
};

// Shades `state` to completion, filling what its probes find missing (or, accepting
// fallbacks, in one pass and filling nothing).
inline void shadeWhole(Frame& f, DynamicPhase& phase, const FrameState& state,
                       const DynamicOptions& o, bool acceptFallbacks = false) {
    phase.begin(state, f.drawn, f.layout, o);
    std::vector<TileRequest> missing = phase.shade(acceptFallbacks);
    for (int pass = 0; !acceptFallbacks && !missing.empty() && pass < 8; ++pass) {
        StaticCosts costs;
        f.statics.fill(missing, f.drawn, costs);
        missing = phase.shade();
    }
    ASSERT_TRUE(phase.complete());
}

}  // namespace mpshade::test
