// test_support.h -- shared helpers for mpshade's tests.
#pragma once

#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#if defined(__SSE__)
#include <xmmintrin.h>
#endif

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

// The calling thread's float mode set for a scope, denormals flushed to zero (and read as
// zero) or kept, and restored after. A static fill's tasks flush them (enableFlushToZero)
// and TBB hands a thread's mode on to the tasks it starts, so a test before another in the
// same process may have left it either way. Without SSE the mode is left as it is.
class FloatMode {
  public:
    explicit FloatMode(bool flush) {
#if defined(__SSE__)
        constexpr unsigned kFlushAndDenormalsZero = 0x8040;  // MXCSR's FTZ and DAZ bits
        saved_ = _mm_getcsr();
        _mm_setcsr(flush ? (saved_ | kFlushAndDenormalsZero) : (saved_ & ~kFlushAndDenormalsZero));
#else
        (void)flush;
#endif
    }
    ~FloatMode() {
#if defined(__SSE__)
        _mm_setcsr(saved_);
#endif
    }
    FloatMode(const FloatMode&) = delete;
    FloatMode& operator=(const FloatMode&) = delete;

  private:
    unsigned saved_ = 0;
};

}  // namespace mpshade::test
