// shader_harness.h -- compiles shader text and runs it over chosen shading points.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "shading/interpreter.h"
#include "shading/shader_compiler.h"

namespace mpshade::test {

struct ShadingPoint {
    glm::vec3 P{0.0f}, N{0, 1, 0}, Ng{0, 1, 0}, dPdu{1, 0, 0}, dPdv{0, 0, -1}, I{0, 0, -1};
    float u = 0, v = 0, s = 0, t = 0;
};

struct ShadingResult {
    std::vector<glm::vec3> Ci, Oi;
    ShadingCounters counters;
};

// Runs `kernel` over the points (all globals as given) with `uniforms`. A kernel that
// reads n-tuple channels gets them from `channelsIn` (one vector per channel); one that
// writes channels fills `channelsOut`.
ShadingResult runKernel(const ShaderKernel& kernel, const std::vector<ShadingPoint>& points,
                        const ShadingUniforms& uniforms = {},
                        const std::vector<std::vector<float>>* channelsIn = nullptr,
                        std::vector<std::vector<float>>* channelsOut = nullptr);

// Compiles `source` with `binding` and runs it.
ShadingResult runShader(const std::string& source, const std::vector<ShadingPoint>& points,
                        const ShaderBinding& binding = {}, const ShadingUniforms& uniforms = {});

}  // namespace mpshade::test
