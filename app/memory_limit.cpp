#include "app/memory_limit.h"

#include <cstdio>
#include <unordered_set>
#include <variant>

#include <sys/resource.h>
#include <unistd.h>

#include "geometry/error.h"
#include "geometry/surface.h"
#include "scene/scene.h"

namespace mpshade {
namespace {

// Of it, 30: what bands keep for a still view (view_reuse.h; 1510 MB against 1283 measured
// at 1920x1080 and 4 spp on examples/vase/lamplight.json).
constexpr uint64_t kMultiphaseBytesPerSample = 270;
constexpr uint64_t kReferenceBytesPerSample = 55;
constexpr uint64_t kBaseBytes = uint64_t{300} << 20;
// Per pixel of each renderer's sample layout: the filter weights summed per pixel (9
// floats), per 2x2 block (16 floats, 4 a pixel) and their inverse sum (SampleLayout).
constexpr uint64_t kFilterBytesPerPixel = (9 + 4 + 1) * sizeof(float);

std::string gigabytes(uint64_t bytes) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.1f GB", static_cast<double>(bytes) / 1e9);
    return buf;
}

}  // namespace

uint64_t physicalMemoryBytes() {
    const long pages = ::sysconf(_SC_PHYS_PAGES), size = ::sysconf(_SC_PAGE_SIZE);
    return pages > 0 && size > 0 ? static_cast<uint64_t>(pages) * static_cast<uint64_t>(size) : 0;
}

uint64_t defaultMemoryLimitBytes() {
    const uint64_t physical = physicalMemoryBytes();
    return physical > 0 ? physical / 4 * 3 : uint64_t{8} << 30;
}

uint64_t peakResidentBytes() {
    struct rusage usage {};
    ::getrusage(RUSAGE_SELF, &usage);
    return static_cast<uint64_t>(usage.ru_maxrss) * 1024;  // Linux reports KiB
}

FrameMemoryEstimate estimateFrameMemory(int width, int height, int spp, bool multiphase,
                                        bool reference, int truthSpp) {
    const uint64_t pixels = static_cast<uint64_t>(width) * static_cast<uint64_t>(height);
    FrameMemoryEstimate e;
    e.bytes = kBaseBytes + pixels * 16 * 4;  // frames of each renderer and the written copies
    if (multiphase)
        e.bytes += pixels *
                   (static_cast<uint64_t>(spp) * kMultiphaseBytesPerSample + kFilterBytesPerPixel);
    if (reference)
        e.bytes +=
            pixels * (static_cast<uint64_t>(spp) * kReferenceBytesPerSample + kFilterBytesPerPixel);
    if (truthSpp > 0)
        e.bytes += pixels * (static_cast<uint64_t>(truthSpp) * kReferenceBytesPerSample +
                             kFilterBytesPerPixel);
    e.what = std::to_string(width) + "x" + std::to_string(height) + " pixels at " +
             std::to_string(spp) + " samples" +
             (multiphase && reference ? " (multiphase and reference)"
              : multiphase            ? " (multiphase)"
                                      : " (reference)") +
             (truthSpp > 0 ? ", truth at " + std::to_string(truthSpp) : "");
    return e;
}

uint64_t estimateRaySceneBytes(const Scene& scene, bool allObjects) {
    std::unordered_set<const Surface*> seen;
    uint64_t bytes = 0;
    for (const SceneObject& obj : scene.objects) {
        if (!allObjects && obj.shader->source.find("occlusion") == std::string::npos) continue;
        if (!seen.insert(obj.surface.get()).second) continue;
        const Surface& surface = *obj.surface;
        const int charts = chartCount(surface);
        for (int c = 0; c < charts; ++c) {
            const auto rate = static_cast<uint64_t>(
                std::visit([&](const auto& s) { return s.tessellationRate(c); }, surface));
            bytes += rate == 0 ? 100 : 2 * rate * rate * 110;
        }
    }
    return bytes;
}

void checkMemory(const FrameMemoryEstimate& estimate, uint64_t limitBytes,
                 const std::string& option) {
    if (estimate.bytes <= limitBytes) return;
    throw InputError({option, 0, 0, {}}, estimate.what + " needs about " +
                                             gigabytes(estimate.bytes) +
                                             ", over the memory limit of " + gigabytes(limitBytes) +
                                             " (--memory-mb): " + estimate.hint);
}

}  // namespace mpshade
