// binding.h -- what a scene says about one object's use of a shader: the value of each
// parameter (default, constant, or animated) and the lights, with which of them move
// relative to the object. Lowering specializes a shader to its binding ("model only what
// the scene needs"): constants fold, and only animated inputs stay inputs.
#pragma once

#include <cctype>
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

// A factoring decision made outside the source (a scene's per-object "factoring", or
// `factor --store/--repeat`): the operation at line:column (an operator, a call's name, as
// the factor report locates values), or the initializer of the variable `name`, is stored (as if
// wrapped in bake(), but only where nothing dynamic reaches it) or repeated every frame (as if
// wrapped in dynamic()).
struct FactoringOverride {
    enum class Kind { Store, Repeat };
    Kind kind = Kind::Store;
    int line = 0, column = 0;  // 0: by name
    std::string name;
    std::string spelled;  // as the user wrote it, for messages
};

// "12:9" (line:column of an operation as `mpshade factor` reports it: an operator, a call's
// name) or a variable's name; false if `text` is neither.
inline bool parseFactoringOverride(const std::string& text, FactoringOverride::Kind kind,
                                   FactoringOverride& out) {
    out = {};
    out.kind = kind;
    out.spelled = text;
    const size_t colon = text.find(':');
    auto digits = [](const std::string& d) {
        return !d.empty() && d.size() < 7 && d.find_first_not_of("0123456789") == std::string::npos;
    };
    if (colon != std::string::npos) {
        const std::string l = text.substr(0, colon), c = text.substr(colon + 1);
        if (!digits(l) || !digits(c)) return false;
        out.line = std::stoi(l);
        out.column = std::stoi(c);
        return out.line > 0 && out.column > 0;
    }
    if (text.empty() || !(std::isalpha(static_cast<unsigned char>(text[0])) || text[0] == '_'))
        return false;
    for (char ch : text)
        if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_')) return false;
    out.name = text;
    return true;
}

struct ShaderBinding {
    std::map<std::string, ParamBinding> params;  // parameters not named take their default
    std::vector<LightBinding> lights;            // in scene order; the light index is the IR's
    std::vector<FactoringOverride> overrides;
};

}  // namespace mpshade
