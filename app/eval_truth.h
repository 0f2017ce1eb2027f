// eval_truth.h -- the ground truth `mpshade eval` measures against: the reference renderer
// at many samples per pixel, cached on disk by what determines it (the bytes of the scene
// file and of every shader and geometry file it names, the image size, the samples and the
// seed), one file per frame, so a second run -- or a longer one -- renders only the frames
// it lacks.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "phases/image.h"

namespace mpshade {

// A 64-bit FNV-1a digest of the scene file and the files it names (shaders, geometry),
// read as bytes. Throws InputError naming a file it cannot read.
uint64_t sceneContentHash(const std::string& scenePath);

struct TruthKey {
    uint64_t sceneHash = 0;
    int width = 0, height = 0, samplesPerPixel = 0;
    uint32_t seed = 0;
    // The cache folder of this key under `root`: root/truth/<16 hex digits>.
    std::filesystem::path folder(const std::filesystem::path& root) const;
};

// The cached truth of one frame, if present and whole (size as the key says).
std::optional<Image> readTruthFrame(const std::filesystem::path& folder, int frame, int width,
                                    int height);
// Writes it atomically (exact floats: a raw little-endian file, not a half-float EXR).
void writeTruthFrame(const std::filesystem::path& folder, int frame, const Image& image);

}  // namespace mpshade
