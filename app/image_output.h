// image_output.h -- reads images (with OpenImageIO, oiio_plugin.h) and writes frames: linear
// half-float RGBA OpenEXR (exr_file.h) and an sRGB-encoded 8-bit PNG for viewing (png_file.h).
#pragma once

#include <string>

#include "phases/image.h"

namespace mpshade {

// Written atomically (output_files.h); throws OutputError naming the file on failure.
// EXR values beyond the half-float range are clamped to +-65504.
void writeExr(const Image& image, const std::string& path);
void writePng(const Image& image, const std::string& path);
// Frame `frame` of a sequence as `render` and `play` write it: DIR/frame_NNNN.exr and .png.
void writeFrameImages(const Image& image, const std::string& dir, int frame);
// Whether both of frame `frame`'s files are in `dir` (written atomically: a file there is
// whole).
bool frameImagesExist(const std::string& dir, int frame);
// Frame `frame`'s shading cost (phases/shading_cost_image.h) as `render --cost-images`
// writes it: DIR/cost_NNNN.exr, float channels "points" and "cost" (opCost units) per
// pixel, and DIR/cost_NNNN.png, the cost as grey from 0 (black) to the frame's most costly
// pixel (white). Returns the EXR's name within `dir`; nothing is written for an empty image
// (and "" returned).
struct ShadingCostImage;
std::string writeShadingCostImages(const ShadingCostImage& cost, const std::string& dir, int frame);
// Reads any image OpenImageIO reads as linear RGBA floats (alpha 1 if it has none; the
// first three channels as RGB, a single channel as grey). Throws InputError naming the
// file when it cannot.
Image readImage(const std::string& path);

}  // namespace mpshade
