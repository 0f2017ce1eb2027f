#include "scene/variability.h"

namespace mpshade {

ObjectVariability variabilityOf(const Scene& scene, const SceneObject& object) {
    ObjectVariability v;
    const Camera& cam = scene.camera;
    v.cameraMoves = cam.eye.varies() || cam.target.varies() || cam.up.varies();
    v.transformAnimated = object.transform.animated();
    // Lights reach the shader in object space (scene_state.cpp, lightsAt): a point light's
    // position there follows every part of the transform, but a distant light's direction
    // only its rotation -- translation leaves directions alone and the scale is uniform.
    // An ambient light has neither: only its color can change.
    const bool rotationAnimated = object.transform.rotate.varies();
    for (const Light& light : scene.lights) {
        const bool animated = light.animated();
        v.lightAnimated.push_back(animated);
        bool moves = animated;
        if (light.kind == LightKind::Distant) moves = animated || rotationAnimated;
        if (light.kind == LightKind::Point) moves = animated || v.transformAnimated;
        v.lightMovesRelative.push_back(moves);
    }
    for (const ParamValue& p : object.params)
        if (p.value.varies()) v.animatedParams.push_back(p.name);
    v.timeVaries = scene.frameCount() > 1;
    return v;
}

ShaderBinding bindingOf(const Scene& scene, const SceneObject& object) {
    ShaderBinding b;
    const ObjectVariability v = variabilityOf(scene, object);
    for (const ParamValue& p : object.params) {
        ParamBinding pb;
        if (p.value.varies()) {
            pb.kind = ParamBinding::Kind::Animated;
        } else {
            pb.kind = ParamBinding::Kind::Constant;
            const glm::vec3 value = p.value.values.front();
            for (int k = 0; k < 3; ++k) pb.value[k] = value[k];
        }
        b.params[p.name] = pb;
    }
    b.overrides = object.factoring;
    for (size_t i = 0; i < scene.lights.size(); ++i) {
        const Light& light = scene.lights[i];
        LightBinding lb;
        lb.kind = light.kind;
        lb.animated = v.lightAnimated[i];
        lb.movesRelativeToObject = v.lightMovesRelative[i];
        const glm::vec3 c = light.color.values.front() * light.intensity.values.front();
        for (int k = 0; k < 3; ++k) lb.color[k] = c[k];
        b.lights.push_back(lb);
    }
    return b;
}

}  // namespace mpshade
