// builtins.h -- the shading language's built-in functions and read-only globals.
#pragma once

#include <string>

#include "shading/types.h"

namespace mpshade {

enum class Builtin {
    // Component-wise math
    Abs,
    Floor,
    Ceil,
    Fract,
    Sqrt,
    Exp,
    Log,
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Sign,
    Min,
    Max,
    Mod,
    Pow,
    Atan2,
    Step,
    Clamp,
    Mix,
    Smoothstep,
    // Vector
    Dot,
    Cross,
    Length,
    Distance,
    Normalize,
    Reflect,
    Faceforward,
    // Pattern
    Noise,
    Snoise,
    Cellnoise,
    Fbm,
    Turbulence,
    // Lighting and visibility
    Ambient,
    Diffuse,
    Specular,
    Phong,
    Occlusion,
    // Factoring overrides
    Bake,
    Dynamic,
    // Constructors and conversions
    MakeColor,
    MakePoint,
    MakeVector,
    MakeNormal,
    MakeFloat,
    MakeInt,
    None
};

Builtin findBuiltin(const std::string& name);
const char* builtinName(Builtin b);

// Read-only globals, each a fixed slot of the shading batch's inputs (see interpreter.h).
enum class GlobalId { P, N, Ng, dPdu, dPdv, I, E, u, v, s, t, time, Count };

bool findGlobal(const std::string& name, GlobalId& id, ValueType& type);
const char* globalName(GlobalId id);
ValueType globalType(GlobalId id);

}  // namespace mpshade
