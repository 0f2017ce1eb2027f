// Fuzz target: the scene loader (JSON, and every file a scene names: shaders through
// factoring for each binding, meshes, patches, points). Any input must load or throw
// InputError; anything else (a crash, a sanitizer report, another exception) is a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_support.h"
#include "geometry/error.h"
#include "scene/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string path = mpshade::fuzz::writeInput("fuzz.json", data, size);
    try {
        const mpshade::Scene scene = mpshade::loadScene(path);
        (void)scene.frameCount();
    } catch (const mpshade::InputError&) {
    }
    return 0;
}
