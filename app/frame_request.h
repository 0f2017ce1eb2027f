// frame_request.h -- what `play` and `profile` ask for: a scene, its frames, the image size
// and samples, each checked (InputError naming the option or the scene), and the memory
// the multi-phase renderer will need checked against the machine's.
#pragma once

#include <cstdint>
#include <string>

#include "phases/frame_stats.h"
#include "phases/reference_renderer.h"
#include "scene/scene.h"

namespace mpshade {

struct FrameRequestOptions {
    std::string scene;   // scene file
    std::string frames;  // "A:B" half-open, or "N"; empty = every frame
    std::string size;    // "WxH"; empty = the scene's
    int spp = -1;        // -1 = the scene's; else 1..1024
    uint32_t seed = 0;
};

struct FrameRequest {
    Scene scene;
    RenderOptions render;                // the options' overrides (0: the scene's)
    int first = 0, last = 0;             // frames [first, last)
    int width = 0, height = 0, spp = 0;  // as rendered
};

FrameRequest loadFrameRequest(const FrameRequestOptions& options);

}  // namespace mpshade
