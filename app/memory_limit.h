// memory_limit.h -- `--memory-mb`: a render that would need more memory than the limit is
// refused before anything is allocated, with the settings that make it so named, instead
// of being killed by the system halfway.
#pragma once

#include <cstdint>
#include <string>

namespace mpshade {

// Physical memory of this machine, in bytes (0 if unknown).
uint64_t physicalMemoryBytes();
// The default limit: three quarters of physical memory or of the container's limit (the
// cgroup's memory.max, v2, or memory.limit_in_bytes, v1, of this process's group and the
// groups above it), whichever is less; 8 GiB if neither is known.
uint64_t defaultMemoryLimitBytes();
// The smallest memory limit of the cgroups `cgroupFile` (as /proc/self/cgroup) names, read
// under `cgroupRoot` (as /sys/fs/cgroup), in bytes; 0 when none is set.
uint64_t cgroupLimitFrom(const std::string& cgroupFile, const std::string& cgroupRoot);
// Peak resident memory of this process so far, in bytes.
uint64_t peakResidentBytes();

// Memory a frame needs, estimated from measured use (teapot at 960x540: 240 bytes per
// sample for multi-phase -- visibility, fragments, shading batches --, 55 for the reference,
// on top of about 300 MB of scene, maps and facets). An estimate, made to refuse requests
// that cannot fit (16384 x 16384 at 1024 spp needs 60 TB), not a promise.
struct FrameMemoryEstimate {
    uint64_t bytes = 0;
    std::string what;  // "960x540 pixels at 32 samples (multiphase and reference)"
    std::string hint = "lower --size or --spp";
};
FrameMemoryEstimate estimateFrameMemory(int width, int height, int spp, bool multiphase,
                                        bool reference, int truthSpp);

struct Scene;
// Memory of the scene's ray-query structures: the exact-surface tessellation and BVH of
// each distinct surface (measured: about 110 bytes a triangle; a sphere takes 2 MB), and
// 100 bytes a disc of a point cloud. Added to a frame's estimate: a scene of 20,000
// different spheres needs 40 GB of them.
// allObjects false (multi-phase alone): only surfaces whose shader may cast occlusion rays
// (its text names occlusion: an over-estimate at worst) are traced.
uint64_t estimateRaySceneBytes(const Scene& scene, bool allObjects);

// Throws InputError naming `option` (or the settings) if the estimate exceeds limitBytes.
void checkMemory(const FrameMemoryEstimate& estimate, uint64_t limitBytes,
                 const std::string& option);

}  // namespace mpshade
