#include "app/frame_request.h"

#include "app/command_line.h"
#include "app/memory_limit.h"
#include "geometry/error.h"

namespace mpshade {

FrameRequest loadFrameRequest(const FrameRequestOptions& options) {
    if (options.spp != -1 && (options.spp < 1 || options.spp > 1024))
        throw InputError({"--spp", 0, 0, {}},
                         "expected 1..1024, found " + std::to_string(options.spp));
    FrameRequest r{loadScene(options.scene), {}, {}, 0, 0, 0};
    r.render.seed = options.seed;
    r.render.samplesPerPixel = options.spp > 0 ? options.spp : 0;
    parseImageSize(options.size, r.render.width, r.render.height);
    parseFrameRange(options.frames, r.scene.frameCount(), r.first, r.last);
    r.resolved = r.render.resolved(r.scene.settings);
    r.memoryLimitBytes =
        options.memoryLimitBytes > 0 ? options.memoryLimitBytes : defaultMemoryLimitBytes();
    FrameMemoryEstimate estimate =
        estimateFrameMemory(r.resolved.width, r.resolved.height, r.resolved.samplesPerPixel,
                            options.multiphase, options.reference, options.truthSpp);
    const uint64_t rays = estimateRaySceneBytes(r.scene, options.reference);
    const bool raysDominate = rays > estimate.bytes;
    estimate.bytes += rays;
    if (raysDominate) {
        estimate.what +=
            " and the ray queries of " + std::to_string(r.scene.objects.size()) + " objects";
        estimate.hint = "fewer distinct shapes (equal ones share)";
    }
    checkMemory(estimate, r.memoryLimitBytes,
                raysDominate                               ? options.scene + ": objects"
                : !options.size.empty() || options.spp > 0 ? "--size/--spp"
                                                           : options.scene + ": settings");
    return r;
}

}  // namespace mpshade
