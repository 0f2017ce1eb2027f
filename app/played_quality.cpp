#include "app/played_quality.h"

#include <cstdio>
#include <filesystem>
#include <utility>

#include "app/eval_metrics.h"
#include "app/image_output.h"
#include "geometry/error.h"
#include "phases/image_compare.h"

namespace mpshade {

PlayedQuality::PlayedQuality(std::string dir) : dir_(std::move(dir)) {
    if (!std::filesystem::is_directory(dir_))
        throw InputError({"--compare-to", 0, 0, {}},
                         "'" + dir_ + "' is not a folder of constant-quality frames");
}

PlayedFrameQuality PlayedQuality::measure(const Image& played, int frame) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%04d.exr", frame);
    const std::string path = (std::filesystem::path(dir_) / name).string();
    if (!std::filesystem::exists(path))
        throw InputError({path, 0, 0, {}},
                         "no constant-quality frame " + std::to_string(frame) +
                             " (render the same frames at the same size into --compare-to)");
    Image truth = readImage(path);
    if (truth.width != played.width || truth.height != played.height)
        throw InputError({path, 0, 0, {}},
                         "is " + std::to_string(truth.width) + "x" + std::to_string(truth.height) +
                             ", the frames played " + std::to_string(played.width) + "x" +
                             std::to_string(played.height));
    PlayedFrameQuality q;
    q.psnr = compareImages(played, truth).psnr;
    if (lastFrame_ == frame - 1)
        q.temporalRmse = temporalRmse(lastPlayed_, played, lastTruth_, truth);
    lastPlayed_ = played;
    lastTruth_ = std::move(truth);
    lastFrame_ = frame;
    frames_.push_back(q);
    return q;
}

}  // namespace mpshade
