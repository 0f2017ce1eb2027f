#include "app/frame_request.h"

#include "app/command_line.h"
#include "app/memory_limit.h"
#include "geometry/error.h"

namespace mpshade {

FrameRequest loadFrameRequest(const FrameRequestOptions& options) {
    if (options.spp != -1 && (options.spp < 1 || options.spp > 1024))
        throw InputError({"--spp", 0, 0, {}},
                         "expected 1..1024, found " + std::to_string(options.spp));
    FrameRequest r{loadScene(options.scene), {}, 0, 0, 0, 0, 0};
    r.render.seed = options.seed;
    r.render.samplesPerPixel = options.spp > 0 ? options.spp : 0;
    parseImageSize(options.size, r.render.width, r.render.height);
    parseFrameRange(options.frames, r.scene.frameCount(), r.first, r.last);
    r.width = r.render.width > 0 ? r.render.width : r.scene.settings.width;
    r.height = r.render.height > 0 ? r.render.height : r.scene.settings.height;
    r.spp = options.spp > 0 ? options.spp : r.scene.settings.samplesPerPixel;
    FrameMemoryEstimate estimate = estimateFrameMemory(r.width, r.height, r.spp, true, false, -1);
    estimate.bytes += estimateRaySceneBytes(r.scene, false);
    checkMemory(
        estimate, defaultMemoryLimitBytes(),
        !options.size.empty() || options.spp > 0 ? "--size/--spp" : options.scene + ": settings");
    return r;
}

}  // namespace mpshade
