// variability.h -- which of an object's shading inputs the scene varies at all, and the
// shader binding that follows (binding.h). The factoring front end cuts each shader per
// object with this: an input the scene never animates is a constant.
#pragma once

#include <string>
#include <vector>

#include "scene/scene.h"
#include "shading/binding.h"

namespace mpshade {

struct ObjectVariability {
    bool cameraMoves = false;  // eye or target keyed: I and E vary
    bool transformAnimated = false;
    // Per scene light: its object-space data changes (a point light: the light or any part of
    // the transform animated; a distant one: the light or the rotation; an ambient one: the
    // light).
    std::vector<bool> lightMovesRelative;
    std::vector<bool> lightAnimated;  // per scene light: any field keyed
    std::vector<std::string> animatedParams;
    bool timeVaries = true;  // `time` is always an input while the scene has more than one frame
};

ObjectVariability variabilityOf(const Scene& scene, const SceneObject& object);
ShaderBinding bindingOf(const Scene& scene, const SceneObject& object);

}  // namespace mpshade
