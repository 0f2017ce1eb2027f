#include "shading/builtins.h"

#include <cstring>

namespace mpshade {
namespace {
const char* const kBuiltinNames[] = {
    "abs",     "floor",       "ceil",     "fract",  "sqrt",      "exp",      "log",
    "sin",     "cos",         "tan",      "asin",   "acos",      "atan",     "sign",
    "min",     "max",         "mod",      "pow",    "atan2",     "step",     "clamp",
    "mix",     "smoothstep",  "dot",      "cross",  "length",    "distance", "normalize",
    "reflect", "faceforward", "noise",    "snoise", "cellnoise", "fbm",      "turbulence",
    "ambient", "diffuse",     "specular", "phong",  "occlusion", "bake",     "dynamic",
    "color",   "point",       "vector",   "normal", "float",     "int"};
static_assert(sizeof(kBuiltinNames) / sizeof(kBuiltinNames[0]) ==
              static_cast<size_t>(Builtin::None));

const struct {
    const char* name;
    ValueType type;
} kGlobals[] = {
    {"P", ValueType::Point},     {"N", ValueType::Normal},    {"Ng", ValueType::Normal},
    {"dPdu", ValueType::Vector}, {"dPdv", ValueType::Vector}, {"I", ValueType::Vector},
    {"E", ValueType::Point},     {"u", ValueType::Float},     {"v", ValueType::Float},
    {"s", ValueType::Float},     {"t", ValueType::Float},     {"time", ValueType::Float}};
static_assert(sizeof(kGlobals) / sizeof(kGlobals[0]) == static_cast<size_t>(GlobalId::Count));
}  // namespace

const char* typeName(ValueType t) {
    switch (t) {
        case ValueType::Float:
            return "float";
        case ValueType::Int:
            return "int";
        case ValueType::Color:
            return "color";
        case ValueType::Point:
            return "point";
        case ValueType::Vector:
            return "vector";
        case ValueType::Normal:
            return "normal";
        case ValueType::Void:
            return "void";
    }
    return "?";
}

Builtin findBuiltin(const std::string& name) {
    for (size_t i = 0; i < static_cast<size_t>(Builtin::None); ++i)
        if (name == kBuiltinNames[i]) return static_cast<Builtin>(i);
    return Builtin::None;
}

const char* builtinName(Builtin b) {
    return b == Builtin::None ? "?" : kBuiltinNames[static_cast<size_t>(b)];
}

bool findGlobal(const std::string& name, GlobalId& id, ValueType& type) {
    for (size_t i = 0; i < static_cast<size_t>(GlobalId::Count); ++i) {
        if (name == kGlobals[i].name) {
            id = static_cast<GlobalId>(i);
            type = kGlobals[i].type;
            return true;
        }
    }
    return false;
}

const char* globalName(GlobalId id) {
    return kGlobals[static_cast<size_t>(id)].name;
}
ValueType globalType(GlobalId id) {
    return kGlobals[static_cast<size_t>(id)].type;
}

}  // namespace mpshade
