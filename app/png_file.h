// png_file.h -- 8-bit RGB PNG files written with libpng (see exr_file.h for why not through
// OpenImageIO).
#pragma once

#include <cstdint>
#include <string>

namespace mpshade {

// Writes width x height RGB bytes (rows top to bottom, not owned) to `path` at zlib level
// `compressionLevel` (0-9), libpng's row filters (not atomically: callers go through
// output_files.h's writeAtomically). Throws std::exception on failure.
void writePngFile(const uint8_t* rgb, int width, int height, int compressionLevel,
                  const std::string& path);

}  // namespace mpshade
