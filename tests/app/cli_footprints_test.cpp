// Footprints by object from the command line: `render` measures them on a sequence long
// enough to repay it, reports what it measured, and `--footprints uniform` renders the
// frames it rendered before.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_support.h"

namespace {

using mpshade::cli::CliRun;
using mpshade::cli::mpshade;
using mpshade::cli::readStats;
using mpshade::cli::tempDir;

TEST(CliFootprints, RenderMeasuresEachObjectOnceAndReportsIt) {
    const std::string measured = tempDir("footprints_measured");
    const std::string uniform = tempDir("footprints_uniform");
    const std::string args =
        "render examples/vase/scene.json --frames 0:24 --size 160x90 --no-store --quiet ";
    const CliRun m = mpshade(args + "--out " + measured);
    ASSERT_EQ(m.exitCode, 0) << m.output;
    const nlohmann::json ms = readStats(measured);
    ASSERT_TRUE(ms["frames"][0].contains("footprint_calibration")) << ms["frames"][0].dump();
    EXPECT_GT(ms["frames"][0]["footprint_calibration"]["objects"].get<int>(), 0);
    for (size_t f = 1; f < ms["frames"].size(); ++f)
        EXPECT_FALSE(ms["frames"][f].contains("footprint_calibration")) << f;
    int reported = 0;
    for (const nlohmann::json& o : ms["objects"]) {
        if (!o.contains("footprint")) continue;
        ++reported;
        const nlohmann::json& fp = o["footprint"];
        EXPECT_GE(fp["scale"].get<double>(), 1.0);
        EXPECT_LE(fp["scale"].get<double>(), 2.0);
        EXPECT_GT(fp["pixels"].get<int>(), 0);
        EXPECT_EQ(fp["scales_tried"].size(), fp["change"].size());
    }
    EXPECT_EQ(reported, ms["frames"][0]["footprint_calibration"]["objects"].get<int>());

    // Uniform: nothing measured, nothing reported.
    const CliRun u = mpshade(args + "--footprints uniform --out " + uniform);
    ASSERT_EQ(u.exitCode, 0) << u.output;
    const nlohmann::json us = readStats(uniform);
    for (const nlohmann::json& f : us["frames"]) EXPECT_FALSE(f.contains("footprint_calibration"));
    for (const nlohmann::json& o : us["objects"]) EXPECT_FALSE(o.contains("footprint"));

    const CliRun bad = mpshade(args + "--footprints wide --out " + uniform);
    EXPECT_EQ(bad.exitCode, 2) << bad.output;
    EXPECT_EQ(bad.output.rfind("mpshade: --footprints: error: expected measured or uniform", 0), 0u)
        << bad.output;
    const CliRun badPlay =
        mpshade("play examples/vase/scene.json --footprints wide --out " + uniform);
    EXPECT_EQ(badPlay.exitCode, 2) << badPlay.output;
    EXPECT_NE(badPlay.output.find("--footprints"), std::string::npos) << badPlay.output;
}

}  // namespace
