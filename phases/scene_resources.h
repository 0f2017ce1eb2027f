// scene_resources.h -- what every renderer builds once per scene: each object's shader
// kernel specialized to its binding, and one Embree scene per distinct surface.
#pragma once

#include <map>
#include <memory>
#include <vector>

#include "geometry/error.h"
#include "geometry/ray_scene.h"
#include "scene/scene.h"
#include "scene/scene_state.h"
#include "shading/interpreter.h"

namespace mpshade {

struct ObjectResources {
    std::shared_ptr<const ShaderKernel> kernel;
    const SurfaceRayScene* rayScene = nullptr;  // owned by SceneResources; may be null
    float occlusionBias = 1e-4f;                // object units
};

// Runs `build` (compiling or factoring an object's shader for its binding) and, when the
// shader cannot be specialized for this object (an animated parameter the shader needs
// constant, say), adds which object and scene bound it to the error.
template <typename F>
auto forObject(const Scene& scene, const SceneObject& object, F&& build) {
    try {
        return build();
    } catch (const InputError& e) {
        throw InputError(e.where(), e.message() + " (binding object '" + object.name + "' of " +
                                        scene.file + ")");
    }
}

class SceneResources {
  public:
    // Which objects get an Embree scene of their surface: all (a ray tracer needs them
    // for camera rays), or only those whose shader casts occlusion rays.
    enum class RayScenes { All, ForOcclusion };
    explicit SceneResources(const Scene& scene, RayScenes rayScenes = RayScenes::All);
    const Scene& scene() const { return scene_; }
    const ObjectResources& object(size_t i) const { return objects_[i]; }
    size_t objectCount() const { return objects_.size(); }
    // Builds every ray scene now, in parallel, rather than at the first ray each meets (a
    // fill that traces occlusion rays): for a frame rate, whose frames must not pay 4-70 ms
    // for a tessellation and its hierarchy (the gallery's objects at 640x360).
    void buildRayScenes() const;

  private:
    const Scene& scene_;
    std::vector<ObjectResources> objects_;
    std::map<const Surface*, std::unique_ptr<SurfaceRayScene>> rayScenes_;
};

// Everything shading needs of one frame at time t, per object: its placement, animated
// parameter block, lights in its coordinates, and the uniforms pointing at them. The spans
// in `uniforms` point into `params` and `lights`, which must not be resized.
struct FrameState {
    int index = 0;                       // the frame's number
    int width = 0, height = 0, spp = 1;  // resolved: the options', else the scene's
    float time = 0.0f;
    CameraState camera;
    std::vector<ObjectState> objects;
    std::vector<std::vector<float>> params;
    std::vector<std::vector<LightSample>> lights;
    std::vector<ShadingUniforms> uniforms;
};

// Whether any of the object's bounding sphere (its surface's bounds, placed by `state`) lies
// inside the camera's view frustum, between its near and far planes.
bool objectInView(const Surface& surface, const ObjectState& state, const CameraState& camera);

// width, height, spp: as rendered, each at least 1 (RenderOptions::resolved).
FrameState frameStateAt(const SceneResources& resources, int frame, int width, int height, int spp);

// The frame's world: Embree instances of each object's surface, placed at time t.
// Instance (geometry) id i is scene object i.
class WorldRayScene {
  public:
    WorldRayScene(const SceneResources& resources, const std::vector<ObjectState>& states);
    ~WorldRayScene();
    WorldRayScene(const WorldRayScene&) = delete;
    WorldRayScene& operator=(const WorldRayScene&) = delete;
    RTCScene scene() const { return scene_; }

  private:
    RTCScene scene_ = nullptr;
};

}  // namespace mpshade
