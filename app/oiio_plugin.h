// oiio_plugin.h -- what mpshade asks of OpenImageIO, behind a plain C interface: reading any
// image it reads (`compare`, `play --quality-from`) and writing the store's tiled, mip-mapped
// export. OpenImageIO lives in a module of its own (mpshade_oiio.so, app/oiio_plugin.cpp),
// loaded the first time one of these runs (app/oiio_loader.h): linked into the binary, its
// library closure (some 260 shared libraries on Debian 12) took every mpshade process 0.4 s
// to start, for commands and frames that never needed it.
#pragma once

#include <cstddef>

extern "C" {

// Bumped whenever a field below changes: a module of another version is refused.
constexpr int kMpshadeOiioPluginVersion = 1;

// A tiled, mip-mapped OpenEXR file of float channels: `levels` square levels, the finest
// first, each `sizes[k]` texels a side, interleaved `channels` floats a texel, rows top to
// bottom (none owned).
struct MpshadeMipmappedExr {
    int levels;
    const int* sizes;
    const float* const* texels;
    int channels;
    const char* const* channelNames;  // `channels` names
    int tileSize;                     // texels a tile side
    int firstLevel;                   // written as the int attribute mpshade:level, plus k
    int attributes;                   // string attributes: names and values
    const char* const* attributeNames;
    const char* const* attributeValues;
};

struct MpshadeOiioPlugin {
    int version;  // kMpshadeOiioPluginVersion
    // The first subimage of `path` as floats: a buffer of width * height * channels
    // (released by freePixels), or null with a message in error[0, errorBytes).
    float* (*readImage)(const char* path, int* width, int* height, int* channels, char* error,
                        size_t errorBytes);
    void (*freePixels)(float* pixels);
    // Writes `image` to `path`: 1, or 0 with a message in error[0, errorBytes).
    int (*writeMipmappedExr)(const char* path, const MpshadeMipmappedExr* image, char* error,
                             size_t errorBytes);
};

// The module's one entry point (looked up by name: kMpshadeOiioEntry).
using MpshadeOiioEntry = const MpshadeOiioPlugin* (*)();
constexpr const char* kMpshadeOiioEntry = "mpshade_oiio_plugin";
}
