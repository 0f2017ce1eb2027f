// image_compare.h -- error of an image against the reference.
#pragma once

#include "phases/image.h"

namespace mpshade {

struct ImageError {
    double rmse = 0.0;          // root mean square difference of RGB, each clamped to [0, 1]
    double psnr = 0.0;          // 10 log10(1 / mse), dB; 99 for identical images
    double maxAbs = 0.0;        // largest difference of one channel
    double coverageDiff = 0.0;  // mean |alpha difference|
};

// Both images must have the same size.
ImageError compareImages(const Image& test, const Image& reference);

// Where they differ: per pixel the absolute difference of each channel of RGB (each clamped
// to [0, 1] first, as compareImages does) times `gain`, alpha 1. Both the same size.
Image differenceImage(const Image& test, const Image& reference, float gain);

}  // namespace mpshade
