#include "phases/static_inputs.h"

#include <algorithm>
#include <cmath>

#include "geometry/error.h"
#include "shading/program_digest.h"

namespace mpshade {

StaticInputs::StaticInputs(const IrProgram& staticPart) {
    const UniformsRead read = uniformsRead(staticPart);
    time_ = read.time;
    params_ = read.paramFloats;
    lights_ = read.lights;
}

size_t StaticInputs::size() const {
    return (time_ ? 1 : 0) + params_.size() + 9 * lights_.size();
}

void StaticInputs::read(const ShadingUniforms& uniforms, std::vector<float>& out) const {
    out.clear();
    if (time_) out.push_back(uniforms.time);
    for (int p : params_) {
        MPSHADE_CHECK(static_cast<size_t>(p) < uniforms.params.size());
        out.push_back(uniforms.params[static_cast<size_t>(p)]);
    }
    for (int l : lights_) {
        MPSHADE_CHECK(static_cast<size_t>(l) < uniforms.lights.size());
        const LightSample& s = uniforms.lights[static_cast<size_t>(l)];
        for (const glm::vec3* v : {&s.color, &s.position, &s.toLight})
            for (int k = 0; k < 3; ++k) out.push_back((*v)[k]);
    }
}

float staticInputChange(std::span<const float> then, std::span<const float> now,
                        std::span<const float> span) {
    MPSHADE_CHECK(then.size() == now.size() && now.size() == span.size());
    float largest = 0.0f;
    for (size_t k = 0; k < now.size(); ++k)
        if (span[k] > 0.0f) largest = std::max(largest, std::fabs(now[k] - then[k]) / span[k]);
    return largest;
}

std::vector<std::vector<float>> staticInputSpans(const SceneResources& resources,
                                                 std::span<const StaticInputs> inputs) {
    const size_t n = inputs.size();
    std::vector<std::vector<float>> lo(n), hi(n);
    if (std::all_of(inputs.begin(), inputs.end(), [](const StaticInputs& s) { return s.empty(); }))
        return lo;
    const int frames = std::max(1, resources.scene().frameCount());
    const int samples = std::min(frames, 256);
    std::vector<float> values;
    for (int k = 0; k < samples; ++k) {
        const int frame =
            samples > 1 ? static_cast<int>(static_cast<int64_t>(k) * (frames - 1) / (samples - 1))
                        : 0;
        const FrameState state = frameStateAt(resources, frame, 1, 1, 1);
        for (size_t i = 0; i < n; ++i) {
            if (inputs[i].empty()) continue;
            inputs[i].read(state.uniforms[i], values);
            if (lo[i].empty()) {
                lo[i] = hi[i] = values;
                continue;
            }
            for (size_t f = 0; f < values.size(); ++f) {
                lo[i][f] = std::min(lo[i][f], values[f]);
                hi[i][f] = std::max(hi[i][f], values[f]);
            }
        }
    }
    for (size_t i = 0; i < n; ++i)
        for (size_t f = 0; f < lo[i].size(); ++f) lo[i][f] = hi[i][f] - lo[i][f];
    return lo;
}

}  // namespace mpshade
