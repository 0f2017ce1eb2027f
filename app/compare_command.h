// compare_command.h -- `mpshade compare`: the error of one image against another.
#pragma once

#include <string>

namespace mpshade {

struct CompareCommandOptions {
    std::string test;       // the image measured
    std::string reference;  // the image it is measured against
    bool json = false;
    std::string difference;  // if set: write the difference image here (.exr or .png)
    float gain = 4.0f;       // the difference image's scale
};

// Prints PSNR, RMSE, largest error and coverage difference, and writes the difference
// image if asked. Returns the exit code, 0. Images that cannot be read or differ in size, or
// a difference image that cannot be written, throw InputError (the CLI exits 2).
int runCompareCommand(const CompareCommandOptions& options);

}  // namespace mpshade
