#include "app/memory_limit.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
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

uint64_t cgroupLimitFrom(const std::string& cgroupFile, const std::string& cgroupRoot) {
    std::ifstream in(cgroupFile);
    std::string line;
    uint64_t limit = 0;
    auto consider = [&](const std::filesystem::path& file) {
        std::ifstream f(file);
        std::string value;
        if (!(f >> value) || value == "max" || value.empty()) return;
        char* end = nullptr;
        const unsigned long long v = std::strtoull(value.c_str(), &end, 10);
        // cgroup v1 writes "no limit" as a huge number rounded to pages.
        if (end && *end == '\0' && v > 0 && v < (uint64_t{1} << 60))
            limit = limit == 0 ? v : std::min<uint64_t>(limit, v);
    };
    while (std::getline(in, line)) {
        // "0::/path" (v2) or "N:memory:/path" (v1, the memory controller).
        const size_t a = line.find(':'), b = a == std::string::npos ? a : line.find(':', a + 1);
        if (b == std::string::npos) continue;
        const std::string controllers = line.substr(a + 1, b - a - 1);
        std::string path = line.substr(b + 1);
        const bool v2 = controllers.empty();
        if (!v2 && controllers.find("memory") == std::string::npos) continue;
        const std::filesystem::path base = std::filesystem::path(cgroupRoot) / (v2 ? "" : "memory");
        // The limit of the group and of every group above it: the smallest holds.
        for (std::filesystem::path p = path;; p = p.parent_path()) {
            consider(base / p.relative_path() / (v2 ? "memory.max" : "memory.limit_in_bytes"));
            if (p == p.parent_path() || p.empty()) break;
        }
    }
    return limit;
}

uint64_t defaultMemoryLimitBytes() {
    uint64_t available = physicalMemoryBytes();
    const uint64_t group = cgroupLimitFrom("/proc/self/cgroup", "/sys/fs/cgroup");
    if (group > 0) available = available > 0 ? std::min(available, group) : group;
    return available > 0 ? available / 4 * 3 : uint64_t{8} << 30;
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
