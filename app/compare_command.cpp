#include "app/compare_command.h"

#include <cstdio>

#include <nlohmann/json.hpp>

#include "app/image_output.h"
#include "geometry/error.h"
#include "phases/image_compare.h"

namespace mpshade {

int runCompareCommand(const CompareCommandOptions& options) {
    const Image test = readImage(options.test);
    const Image reference = readImage(options.reference);
    if (test.width != reference.width || test.height != reference.height)
        throw InputError({options.test, 0, 0, {}},
                         "is " + std::to_string(test.width) + "x" + std::to_string(test.height) +
                             " but the reference is " + std::to_string(reference.width) + "x" +
                             std::to_string(reference.height));
    const ImageError e = compareImages(test, reference);
    if (!options.difference.empty()) {
        const Image d = differenceImage(test, reference, options.gain);
        const std::string& path = options.difference;
        const bool exr = path.size() >= 4 && path.compare(path.size() - 4, 4, ".exr") == 0;
        try {
            exr ? writeExr(d, path) : writePng(d, path);
        } catch (const std::runtime_error& err) {
            throw InputError({path, 0, 0, {}}, std::string("cannot be written: ") + err.what());
        }
    }
    if (options.json) {
        const nlohmann::json doc = {{"psnr_db", e.psnr},
                                    {"rmse", e.rmse},
                                    {"max_abs_error", e.maxAbs},
                                    {"coverage_difference", e.coverageDiff}};
        std::printf("%s\n", doc.dump(2).c_str());
    } else {
        std::printf("PSNR %.2f dB, RMSE %.5f, largest error %.4f, coverage difference %.2e\n",
                    e.psnr, e.rmse, e.maxAbs, e.coverageDiff);
    }
    return 0;
}

}  // namespace mpshade
