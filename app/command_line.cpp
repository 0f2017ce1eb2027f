#include "app/command_line.h"

#include "geometry/error.h"

namespace mpshade {

bool parseWholeNumber(const std::string& s, long& out) {
    if (s.empty() || s.size() > 9) return false;
    for (char c : s)
        if (c < '0' || c > '9') return false;
    out = std::stol(s);
    return true;
}

void parseFrameRange(const std::string& spec, int frameCount, int& first, int& last,
                     const std::string& scene) {
    first = 0;
    last = frameCount;
    if (spec.empty()) return;
    const InputLocation where{"--frames", 0, 0, {}};
    long a, b;
    const auto colon = spec.find(':');
    if (colon == std::string::npos) {
        if (!parseWholeNumber(spec, a))
            throw InputError(where, "expected A:B or N, found '" + spec + "'");
        b = a + 1;
    } else if (!parseWholeNumber(spec.substr(0, colon), a) ||
               !parseWholeNumber(spec.substr(colon + 1), b)) {
        throw InputError(where, "expected A:B with whole numbers, found '" + spec + "'");
    }
    if (!(a < b))
        throw InputError(
            where, "the range " + spec + " is empty (frames are half-open: 0:2 is frames 0 and 1)");
    if (b > frameCount)
        throw InputError(where, "the range " + spec + " goes past " + scene + "'s " +
                                    std::to_string(frameCount) +
                                    " frames (0:" + std::to_string(frameCount) + ")");
    first = static_cast<int>(a);
    last = static_cast<int>(b);
}

void parseImageSize(const std::string& spec, int& width, int& height) {
    if (spec.empty()) return;
    const auto x = spec.find('x');
    long w, h;
    if (x == std::string::npos || !parseWholeNumber(spec.substr(0, x), w) ||
        !parseWholeNumber(spec.substr(x + 1), h) || w < 1 || h < 1 || w > 16384 || h > 16384)
        throw InputError({"--size", 0, 0, {}},
                         "expected WxH with each in 1..16384, found '" + spec + "'");
    width = static_cast<int>(w);
    height = static_cast<int>(h);
}

}  // namespace mpshade
