// `mpshade play` with refinement by tile and against constant-quality frames
// (--refine, --refine-tile, --compare-to): what stats.json and the summary say, and bad
// values refused with exit code 2 naming the option or the file.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_support.h"

namespace {

using mpshade::cli::CliRun;
using mpshade::cli::mpshade;
using mpshade::cli::readStats;
using mpshade::cli::tempDir;

TEST(CliPlay, MeasuresEachFrameAgainstConstantQualityAndReportsRefinement) {
    const std::string truth = tempDir("play_truth");
    const CliRun render = mpshade(
        "render examples/teapot/scene.json --frames 0:3 --size 96x54 --no-single-phase --quiet "
        "--out " +
        truth);
    ASSERT_EQ(render.exitCode, 0) << render.output;
    for (const char* refine : {"on", "off"}) {
        const std::string out = tempDir(std::string("play_compared_") + refine);
        const CliRun run = mpshade(
            std::string("play examples/teapot/scene.json --frames 0:3 --size 96x54 --fps 10 ") +
            "--refine " + refine + " --compare-to " + truth + " --out " + out);
        ASSERT_EQ(run.exitCode, 0) << run.output;
        EXPECT_NE(run.output.find("against the constant-quality frames: median"), std::string::npos)
            << run.output;
        const nlohmann::json stats = readStats(out);
        ASSERT_EQ(stats["frames"].size(), 3u);
        for (size_t k = 0; k < 3; ++k) {
            const nlohmann::json& f = stats["frames"][k];
            const double psnr = f["constant_quality"]["psnr"].get<double>();
            EXPECT_GT(psnr, 20.0);
            EXPECT_LE(psnr, 99.0);
            // The temporal error needs a frame before.
            EXPECT_EQ(f["constant_quality"].contains("temporal_rmse"), k > 0);
            if (!f.contains("refine")) continue;
            EXPECT_EQ(std::string(refine), "on");
            const nlohmann::json& r = f["refine"];
            EXPECT_EQ(r["tile_size"], 16);
            double share = 0.0;
            // From the frame's own step up, each a rate or footprint of its own.
            ASSERT_GE(r["steps"].size(), 2u);
            EXPECT_EQ(r["steps"][0]["shading_rate"], f["quality"]["shading_rate"]);
            EXPECT_EQ(r["steps"][0]["footprint_scale"], f["quality"]["footprint_scale"]);
            EXPECT_EQ(r["steps"].back()["shading_rate"], "sample");
            EXPECT_EQ(r["steps"].back()["footprint_scale"], 1.0);
            for (size_t a = 0; a < r["steps"].size(); ++a)
                for (size_t b = 0; b < a; ++b)
                    EXPECT_FALSE(r["steps"][a]["shading_rate"] == r["steps"][b]["shading_rate"] &&
                                 r["steps"][a]["footprint_scale"] ==
                                     r["steps"][b]["footprint_scale"]);
            for (const nlohmann::json& s : r["steps"]) share += s["pixel_share"].get<double>();
            EXPECT_NEAR(share, 1.0, 1e-9);
        }
    }
}

TEST(CliPlay, RefusesBadRefinementAndComparisonOptions) {
    const std::string out = tempDir("play_bad");
    for (const char* bad : {"--refine maybe", "--refine-tile 5", "--refine-tile 2",
                            "--refine-tile 512", "--compare-to no/such/folder"}) {
        const CliRun r = mpshade(std::string("play examples/teapot/scene.json --frames 0:1 ") +
                                 bad + " --out " + out);
        EXPECT_EQ(r.exitCode, 2) << bad << ": " << r.output;
        const std::string option = std::string(bad).substr(0, std::string(bad).find(' '));
        EXPECT_NE(r.output.find(option), std::string::npos) << r.output;
    }
    // Constant-quality frames of another size, or missing: the file is named.
    const std::string truth = tempDir("play_truth_small");
    ASSERT_EQ(mpshade("render examples/teapot/scene.json --frames 0:1 --size 48x27 --quiet "
                      "--no-single-phase --out " +
                      truth)
                  .exitCode,
              0);
    const CliRun size = mpshade(
        "play examples/teapot/scene.json --frames 0:1 --size 96x54 "
        "--compare-to " +
        truth + " --out " + out);
    EXPECT_EQ(size.exitCode, 2) << size.output;
    EXPECT_NE(size.output.find("frame_0000.exr"), std::string::npos) << size.output;
    const CliRun missing = mpshade(
        "play examples/teapot/scene.json --frames 1:2 --size 48x27 "
        "--compare-to " +
        truth + " --out " + out);
    EXPECT_EQ(missing.exitCode, 2) << missing.output;
    EXPECT_NE(missing.output.find("frame_0001.exr"), std::string::npos) << missing.output;
}

}  // namespace
