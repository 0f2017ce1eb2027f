// frame_request.h -- what `render`, `play` and `profile` ask for: a scene, its frames, the
// image size and samples, each checked (InputError naming the option or the scene), and the
// memory the renderers will need checked against the limit.
#pragma once

#include <cstdint>
#include <string>

#include "phases/renderer.h"
#include "scene/scene.h"

namespace mpshade {

struct FrameRequestOptions {
    std::string scene;   // scene file
    std::string frames;  // "A:B" half-open, or "N"; empty = every frame
    std::string size;    // "WxH"; empty = the scene's
    int spp = -1;        // -1 = the scene's; else 1..1024
    uint32_t seed = 0;
    // What the memory estimate counts: the multi-phase renderer's frame, the reference's
    // (and the ray queries of every object), and a truth at this many samples (-1: none);
    // checked against memoryLimitBytes (0: the machine's default, memory_limit.h).
    bool multiphase = true;
    bool reference = false;
    int truthSpp = -1;
    uint64_t memoryLimitBytes = 0;
};

struct FrameRequest {
    Scene scene;
    RenderOptions render;           // the options' overrides (0: the scene's)
    RenderOptions resolved;         // the same over the scene's settings: the frame as rendered
    int first = 0, last = 0;        // frames [first, last)
    uint64_t memoryLimitBytes = 0;  // as checked
};

FrameRequest loadFrameRequest(const FrameRequestOptions& options);

}  // namespace mpshade
