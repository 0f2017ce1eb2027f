// exr_file.h -- scanline OpenEXR files written with the OpenEXR library itself. OpenImageIO
// (app/oiio_plugin.h) reads images and writes the store's mip-mapped export, but it is not
// linked into the mpshade binary: its library closure (some 260 shared libraries on Debian
// 12) took every mpshade process 0.4 s to start, before main, for a frame's EXR that
// OpenEXR writes alone.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace mpshade {

struct ExrChannel {
    std::string name;
    bool half = true;  // stored as binary16 (values rounded to nearest); false: float32
};

// An image of `channels` interleaved floats per pixel, rows top to bottom; not owned.
struct ExrImage {
    int width = 0, height = 0;
    std::vector<ExrChannel> channels;
    const float* pixels = nullptr;  // width * height * channels.size()
    std::vector<std::pair<std::string, std::string>> attributes;  // string attributes
};

// Writes `image` ZIP-compressed to `path` (not atomically: callers go through
// output_files.h's writeAtomically). Throws std::exception on failure.
void writeExrFile(const ExrImage& image, const std::string& path);

}  // namespace mpshade
