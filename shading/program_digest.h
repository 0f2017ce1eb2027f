// program_digest.h -- what a compiled program computes, as a digest: its operations,
// constants and outputs (not its names, source positions or comments, so re-formatting a
// shader keeps its digest), and the uniform values it reads. Two programs with equal digests
// given equal inputs give equal outputs, bit for bit: the shader-map store
// (shadermaps/tile_store.h) relies on it to share tiles between runs and machines.
#pragma once

#include <vector>

#include "geometry/content_digest.h"
#include "shading/interpreter.h"

namespace mpshade {

// The uniforms a program reads: its animated parameter floats and lights (sorted, each
// once), and whether it reads the eye (E, or I, which the static phase computes from it),
// the time, and occlusion (the bias).
struct UniformsRead {
    std::vector<int> paramFloats, lights;
    bool eye = false, time = false, occlusion = false;
};
UniformsRead uniformsRead(const IrProgram& program);

// Adds the program's canonical form to `hasher`.
void addProgram(ContentHasher& hasher, const IrProgram& program);

// Adds the values of `uniforms` that `program` reads: each animated parameter it loads,
// each light it lights by (kind, color, position, direction), the eye where it reads E or
// I (the static phase computes I from the eye), the time where it reads it, and the
// occlusion bias where it traces occlusion. A uniform it does not read is not added, so
// moving the camera leaves the digest of a program that never sees the view unchanged.
void addUniformsRead(ContentHasher& hasher, const IrProgram& program,
                     const ShadingUniforms& uniforms);

// Bumped whenever what a program evaluates to changes for the same digest (the
// interpreter's arithmetic, a builtin such as noise, the lighting model): stores made by an
// older build are then never read.
inline constexpr uint64_t kEvaluationVersion = 1;

}  // namespace mpshade
