// test_support.h -- shared helpers for mpshade's tests.
#pragma once

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace mpshade::test {

// A path inside the source tree, e.g. sourcePath("examples/vase/scene.json").
inline std::string sourcePath(const std::string& relative) {
    return std::string(MPSHADE_SOURCE_DIR) + "/" + relative;
}

// A folder of the running test's own, made if missing, ending in '/': ctest runs tests
// in parallel processes, and one rewriting a scene or shader file that another is reading
// made it read a file cut short.
inline std::string testFolder(const std::string& prefix) {
    const std::string dir = ::testing::TempDir() + prefix + "_" +
                            ::testing::UnitTest::GetInstance()->current_test_info()->name() + "/";
    std::filesystem::create_directories(dir);
    return dir;
}

}  // namespace mpshade::test
