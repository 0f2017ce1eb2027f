// compare_command.h -- `mpshade compare`: the error of one image against another.
#pragma once

#include <string>

namespace mpshade {

struct CompareCommandOptions {
    std::string test;       // the image measured
    std::string reference;  // the image it is measured against
    bool json = false;
};

// Prints PSNR, RMSE, largest error and coverage difference. Returns the exit code: 0, or
// 2 for images that cannot be read or differ in size (message on stderr).
int runCompareCommand(const CompareCommandOptions& options);

}  // namespace mpshade
