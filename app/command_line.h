// command_line.h -- the option values the commands share: frame ranges and image sizes.
// Bad values throw InputError naming the option (the CLI's exit status 2).
#pragma once

#include <string>

namespace mpshade {

// A whole number of at most 9 digits, no sign.
bool parseWholeNumber(const std::string& s, long& out);

// --frames "A:B" (half-open) or "N", checked against `frameCount` frames of `scene` (as
// the message names it). Empty: every frame, [0, frameCount).
void parseFrameRange(const std::string& spec, int frameCount, int& first, int& last,
                     const std::string& scene = "the scene");

// --size "WxH", each in 1..16384. Empty: width and height are left as they are.
void parseImageSize(const std::string& spec, int& width, int& height);

}  // namespace mpshade
