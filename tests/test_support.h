// test_support.h -- shared helpers for mpshade's tests.
#pragma once

#include <string>

namespace mpshade::test {

// A path inside the source tree, e.g. sourcePath("examples/vase/scene.json").
inline std::string sourcePath(const std::string& relative) {
    return std::string(MPSHADE_SOURCE_DIR) + "/" + relative;
}

}  // namespace mpshade::test
