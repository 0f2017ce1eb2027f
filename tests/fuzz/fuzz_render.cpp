// Fuzz target: a scene end to end -- loaded, then its first frame rendered at 4 x 3 pixels
// and 1 sample by both renderers. Frames must be finite; bad scenes throw InputError.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "fuzz/fuzz_support.h"
#include "geometry/error.h"
#include "controller/multiphase_renderer.h"
#include "phases/reference_renderer.h"
#include "scene/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string path = mpshade::fuzz::writeInput("fuzz_render.json", data, size);
    try {
        const mpshade::Scene scene = mpshade::loadScene(path);
        mpshade::RenderOptions options;
        options.width = 4;
        options.height = 3;
        options.samplesPerPixel = 1;
        mpshade::FrameStats stats;
        const mpshade::Image ref = mpshade::ReferenceRenderer(scene).renderFrame(0, options, stats);
        mpshade::MultiphaseRenderer multi(scene);
        const mpshade::Image mp = multi.renderFrame(0, options, stats);
        for (const mpshade::Image* image : {&ref, &mp})
            for (float v : image->rgba)
                if (!std::isfinite(v)) std::abort();  // a finding: frames are always finite
    } catch (const mpshade::InputError&) {
    }
    return 0;
}
