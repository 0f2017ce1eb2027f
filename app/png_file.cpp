#include "app/png_file.h"

#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include <png.h>

namespace mpshade {
namespace {

// libpng reports errors by longjmp to the writer's setjmp; the message is kept for it.
struct PngErrors {
    char message[256] = "libpng failed";
};

void onError(png_structp png, png_const_charp message) {
    auto* errors = static_cast<PngErrors*>(png_get_error_ptr(png));
    std::snprintf(errors->message, sizeof errors->message, "%s", message);
    png_longjmp(png, 1);
}

void onWarning(png_structp, png_const_charp) {}

// The libpng calls alone, between the setjmp and its return no object with a destructor:
// the longjmp of an error skips destructors. False on an error (the message in `errors`).
bool writeRows(std::FILE* file, const uint8_t* rgb, int width, int height, int level,
               PngErrors& errors) {
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &errors, onError, onWarning);
    if (!png) return false;
    png_infop info = png_create_info_struct(png);
    if (!info || setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return false;
    }
    png_init_io(png, file);
    png_set_compression_level(png, level);
    png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8,
                 PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    for (int y = 0; y < height; ++y)
        png_write_row(png, rgb + static_cast<size_t>(y) * static_cast<size_t>(width) * 3);
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    return true;
}

}  // namespace

void writePngFile(const uint8_t* rgb, int width, int height, int compressionLevel,
                  const std::string& path) {
    if (width < 1 || height < 1 || !rgb) throw std::invalid_argument("an empty image");
    std::FILE* file = std::fopen(path.c_str(), "wb");
    if (!file) throw std::runtime_error(std::strerror(errno));
    PngErrors errors;
    const bool written = writeRows(file, rgb, width, height, compressionLevel, errors);
    const bool closed = std::fclose(file) == 0;
    if (!written) throw std::runtime_error(errors.message);
    if (!closed) throw std::runtime_error(std::strerror(errno));
}

}  // namespace mpshade
