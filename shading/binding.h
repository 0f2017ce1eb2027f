// binding.h -- what a scene says about one object's use of a shader: the value of each
// parameter (default, constant, or animated) and the lights, with which of them move
// relative to the object. Lowering specializes a shader to its binding ("model only what
// the scene needs"): constants fold, and only animated inputs stay inputs.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace mpshade {

enum class LightKind { Ambient, Distant, Point };

struct LightBinding {
    LightKind kind = LightKind::Distant;
    // Any field of the light is keyed (its object-space data or color changes over time).
    bool animated = false;
    // The light moves relative to the object (the light or the object is animated).
    bool movesRelativeToObject = false;
    // color * intensity; used to fold an ambient light that is not animated.
    float color[3] = {0.0f, 0.0f, 0.0f};
};

struct ParamBinding {
    enum class Kind { Default, Constant, Animated };
    Kind kind = Kind::Default;
    float value[3] = {0.0f, 0.0f, 0.0f};  // Constant: the value (1 or 3 components used)
};

struct ShaderBinding {
    std::map<std::string, ParamBinding> params;  // parameters not named take their default
    std::vector<LightBinding> lights;            // in scene order; the light index is the IR's
};

}  // namespace mpshade
