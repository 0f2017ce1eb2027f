// played_quality.h -- `play --compare-to DIR`: each played frame against the constant-quality
// frame of the same index in DIR (as `render` writes them: frame_NNNN.exr), its PSNR and its
// temporal error against the previous played frame (eval_metrics.h), measured outside the
// frame's time as writing it is.
#pragma once

#include <string>
#include <vector>

#include "phases/image.h"

namespace mpshade {

struct PlayedFrameQuality {
    double psnr = 0.0;           // dB against the constant-quality frame
    double temporalRmse = -1.0;  // against the previous frame played (-1: none before it)
};

class PlayedQuality {
  public:
    // Throws InputError naming `dir` when it is not a folder.
    explicit PlayedQuality(std::string dir);

    // Frame `frame` as played; throws InputError naming the file when its constant-quality
    // frame is missing, unreadable or of another size.
    PlayedFrameQuality measure(const Image& played, int frame);

    const std::vector<PlayedFrameQuality>& frames() const { return frames_; }

  private:
    std::string dir_;
    Image lastPlayed_, lastTruth_;
    int lastFrame_ = -2;
    std::vector<PlayedFrameQuality> frames_;
};

}  // namespace mpshade
