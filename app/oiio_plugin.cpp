// The OpenImageIO module (oiio_plugin.h): built as mpshade_oiio.so, loaded on first use.
// OpenImageIO bundles fmt with libfmt's include guards: include fmt first (see docs/building.md).
#include <fmt/format.h>

#include "app/oiio_plugin.h"

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include <OpenImageIO/imageio.h>

namespace {

void report(char* error, size_t errorBytes, const std::string& message) {
    if (error && errorBytes > 0) std::snprintf(error, errorBytes, "%s", message.c_str());
}

float* readImage(const char* path, int* width, int* height, int* channels, char* error,
                 size_t errorBytes) {
    try {
        auto in = OIIO::ImageInput::open(path);
        if (!in) {
            report(error, errorBytes, OIIO::geterror());
            return nullptr;
        }
        const OIIO::ImageSpec& spec = in->spec();
        if (spec.width < 1 || spec.height < 1 || spec.nchannels < 1 || spec.width > 65536 ||
            spec.height > 65536 || spec.nchannels > 1024) {
            report(error, errorBytes, "its size or channel count is out of range");
            return nullptr;
        }
        const size_t count = static_cast<size_t>(spec.width) * static_cast<size_t>(spec.height) *
                             static_cast<size_t>(spec.nchannels);
        auto* pixels = static_cast<float*>(std::malloc(count * sizeof(float)));
        if (!pixels) {
            report(error, errorBytes, "out of memory");
            return nullptr;
        }
        if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels)) {
            report(error, errorBytes, in->geterror());
            std::free(pixels);
            return nullptr;
        }
        *width = spec.width, *height = spec.height, *channels = spec.nchannels;
        return pixels;
    } catch (const std::exception& e) {
        report(error, errorBytes, e.what());
        return nullptr;
    }
}

void freePixels(float* pixels) {
    std::free(pixels);
}

int writeMipmappedExr(const char* path, const MpshadeMipmappedExr* image, char* error,
                      size_t errorBytes) {
    try {
        auto out = OIIO::ImageOutput::create("openexr");
        if (!out) {
            report(error, errorBytes, OIIO::geterror());
            return 0;
        }
        for (int k = 0; k < image->levels; ++k) {
            const int size = image->sizes[k];
            OIIO::ImageSpec spec(size, size, image->channels, OIIO::TypeDesc::FLOAT);
            spec.channelnames.assign(image->channelNames, image->channelNames + image->channels);
            spec.alpha_channel = -1;
            spec.tile_width = spec.tile_height = image->tileSize;
            spec.attribute("compression", "zip");
            spec.attribute("textureformat", "Plain Texture");
            spec.attribute("openexr:levelmode", 1);     // MIPMAP_LEVELS
            spec.attribute("openexr:roundingmode", 0);  // ROUND_DOWN: R / 2^L
            for (int a = 0; a < image->attributes; ++a)
                spec.attribute(image->attributeNames[a], image->attributeValues[a]);
            spec.attribute("mpshade:level", image->firstLevel + k);
            const auto mode =
                k == 0 ? OIIO::ImageOutput::Create : OIIO::ImageOutput::AppendMIPLevel;
            if (!out->open(path, spec, mode) ||
                !out->write_image(OIIO::TypeDesc::FLOAT, image->texels[k])) {
                report(error, errorBytes, out->geterror());
                return 0;
            }
        }
        if (!out->close()) {
            report(error, errorBytes, out->geterror());
            return 0;
        }
        return 1;
    } catch (const std::exception& e) {
        report(error, errorBytes, e.what());
        return 0;
    }
}

constexpr MpshadeOiioPlugin kPlugin{kMpshadeOiioPluginVersion, readImage, freePixels,
                                    writeMipmappedExr};

}  // namespace

extern "C" __attribute__((visibility("default"))) const MpshadeOiioPlugin* mpshade_oiio_plugin() {
    return &kPlugin;
}
