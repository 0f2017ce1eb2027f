// static_inputs.h -- the photometric fiducial of the re-run triggers (Lengyel & Snyder
// 1997, sec. 5: how far the inputs of a cached rendering moved since it was made). An
// object's static part may read animated inputs through bake() (shading-language.md:
// "evaluated at the range's representative control values"): time, animated parameters,
// lights. Its shader map holds their values at the frame the static phase ran, so the
// static phase is due again once any of them moved by more than a tolerance -- a share of
// how far that input moves over the whole scene (its span), so the test reads the same for
// a parameter animated over 0..1 as for one over 0..1000.
#pragma once

#include <span>
#include <vector>

#include "phases/scene_resources.h"
#include "shading/interpreter.h"
#include "shading/ir.h"

namespace mpshade {

class StaticInputs {
  public:
    StaticInputs() = default;
    // The inputs `staticPart` reads that a frame can change.
    explicit StaticInputs(const IrProgram& staticPart);

    bool empty() const { return !time_ && params_.empty() && lights_.empty(); }
    // Floats read() writes.
    size_t size() const;
    // The inputs' values in `uniforms`, in a fixed order: time, the parameter floats, then
    // per light read its color, position and direction.
    void read(const ShadingUniforms& uniforms, std::vector<float>& out) const;

  private:
    bool time_ = false;
    std::vector<int> params_;  // floats of the parameter block
    std::vector<int> lights_;  // light indices
};

// How far the inputs moved from `then` to `now` (both from read()), as the largest of
// |now - then| / span over the floats whose span (how far each moves over the scene,
// max - min) is positive. 0 when nothing moved.
float staticInputChange(std::span<const float> then, std::span<const float> now,
                        std::span<const float> span);

// Per object, per float of its inputs' read(): its span over the scene (max - min over up
// to 256 of its frames, spread evenly from the first to the last). Empty for an object
// whose inputs are.
std::vector<std::vector<float>> staticInputSpans(const SceneResources& resources,
                                                 std::span<const StaticInputs> inputs);

}  // namespace mpshade
