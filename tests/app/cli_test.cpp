// The mpshade command line as a user runs it: exit codes, messages naming the place,
// and images OpenImageIO reads back.
#include <fmt/format.h>

#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_support.h"

namespace {

using mpshade::cli::CliRun;
using mpshade::cli::mpshade;
using mpshade::cli::tempDir;

TEST(Cli, RendersTheVaseToReadableFrames) {
    const std::string out = tempDir("vase");
    const CliRun run = mpshade(
        "render examples/vase/scene.json --mode reference --frames 0:2 --size 160x90 --out " + out);
    ASSERT_EQ(run.exitCode, 0) << run.output;
    for (const char* frame : {"frame_0000", "frame_0001"}) {
        OIIO::ImageBuf exr(out + "/" + frame + ".exr");
        ASSERT_TRUE(exr.read()) << exr.geterror();
        EXPECT_EQ(exr.spec().width, 160);
        EXPECT_EQ(exr.spec().nchannels, 4);
        const auto stats = OIIO::ImageBufAlgo::computePixelStats(exr);
        for (int c = 0; c < 4; ++c) {
            EXPECT_EQ(stats.nancount[c], 0u);
            EXPECT_EQ(stats.infcount[c], 0u);
        }
        // Not blank: the vase and floor cover much of the frame, with real contrast.
        EXPECT_GT(stats.avg[3], 0.3f);
        EXPECT_GT(stats.stddev[0], 0.05f);
        OIIO::ImageBuf png(out + "/" + frame + ".png");
        ASSERT_TRUE(png.read()) << png.geterror();
        EXPECT_EQ(png.spec().nchannels, 3);
    }
    std::ifstream statsFile(out + "/stats.json");
    const nlohmann::json stats = nlohmann::json::parse(statsFile);
    ASSERT_EQ(stats["frames"].size(), 2u);
    EXPECT_EQ(stats["frames"][1]["index"], 1);
    EXPECT_NEAR(stats["frames"][1]["time"].get<double>(), 1.0 / 24.0, 1e-6);
    EXPECT_EQ(stats["frames"][0]["samples"], 160 * 90 * 4);
    EXPECT_GT(stats["frames"][0]["shader_instructions"].get<double>(), 0.0);
    EXPECT_GT(stats["frames"][0]["rays"].get<double>(), 0.0);
    EXPECT_GT(stats["frames"][0]["wall_seconds"].get<double>(), 0.0);
    // Without a terminal (a farm's log): a plain line a frame, no bar redrawn with \r.
    EXPECT_NE(run.output.find("frame 0 done (1 of 2)"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("frame 1 done (2 of 2)"), std::string::npos) << run.output;
    EXPECT_EQ(run.output.find('\r'), std::string::npos) << run.output;
}

TEST(Cli, MultiphaseComparesWithTheReference) {
    const std::string out = tempDir("multiphase");
    const CliRun run = mpshade(
        "render examples/teapot/scene.json --mode multiphase --compare --frames 0:2 --size 96x64 "
        "--spp 2 --out " +
        out);
    ASSERT_EQ(run.exitCode, 0) << run.output;
    std::ifstream statsFile(out + "/stats.json");
    const nlohmann::json stats = nlohmann::json::parse(statsFile);
    EXPECT_EQ(stats["mode"], "multiphase");
    ASSERT_EQ(stats["frames"].size(), 2u);
    // Two frames alone would go single-phase; --compare keeps every frame multi-phase.
    EXPECT_EQ(stats["frames"][0]["single_phase"], false);
    EXPECT_EQ(stats["frames"][0]["static_runs"], 2);  // the teapot and the table
    EXPECT_EQ(stats["frames"][1]["static_runs"], 0);  // frame 1 is inside both ranges
    EXPECT_GT(stats["frames"][0]["facets"].get<double>(), 1000.0);
    for (const auto& frame : stats["frames"]) {
        // Against the 2-sample reference, whose own noise counts as error here.
        EXPECT_GT(frame["reference"]["psnr_db"].get<double>(), 28.0);
        EXPECT_LT(frame["reference"]["coverage_difference"].get<double>(), 0.02);
    }
    EXPECT_NE(run.output.find("PSNR"), std::string::npos);
    OIIO::ImageBuf exr(out + "/frame_0001.exr");
    ASSERT_TRUE(exr.read());
    const auto pixels = OIIO::ImageBufAlgo::computePixelStats(exr);
    EXPECT_EQ(pixels.nancount[0], 0u);
    EXPECT_GT(pixels.avg[3], 0.3f);
}

TEST(Cli, TheGrazingFloorGoesDirectAndSaysWhy) {
    // Its map's fills price far above the reference's work within a frame of being built:
    // from frame 2 the floor is direct, the frame that switched says why, and the object's
    // report gives the priced figures and the reason.
    const std::string out = tempDir("grazing_direct");
    const CliRun run = mpshade(
        "render examples/hard/grazing_floor.json --frames 0:4 --size 96x54 "
        "--compare --out " +
        out);
    ASSERT_EQ(run.exitCode, 0) << run.output;
    std::ifstream statsFile(out + "/stats.json");
    const nlohmann::json stats = nlohmann::json::parse(statsFile);
    const nlohmann::json& ground = stats["objects"][0];
    EXPECT_EQ(ground["representation"], "direct");
    EXPECT_NE(ground["reason"].get<std::string>().find("reference"), std::string::npos);
    EXPECT_GT(ground["priced_ms_per_frame"]["stored"].get<double>(),
              4.0 * ground["priced_ms_per_frame"]["reference"].get<double>());
    bool switched = false;
    for (const auto& frame : stats["frames"])
        for (const auto& due : frame["static_runs_due"])
            switched =
                switched || due["cause"].get<std::string>().find("direct") != std::string::npos;
    EXPECT_TRUE(switched);
    EXPECT_EQ(stats["frames"][3]["tiles_filled"], 0);
}

// The value of a PSNR in eval.json: a number, or "inf" for an exact match.
double psnrValue(const nlohmann::json& v) {
    if (v.is_string() && v == "inf") return INFINITY;
    return v.get<double>();
}

TEST(Cli, EvalWritesFrontsRatiosReportAndReusesTheTruth) {
    const std::string out = tempDir("eval");
    const std::string args =
        "eval tests/data/scenes/ball.json --quick --frames 0:3 --truth-spp 8 --out " + out;
    const CliRun run = mpshade(args);
    ASSERT_EQ(run.exitCode, 0) << run.output;
    std::ifstream file(out + "/eval.json");
    const nlohmann::json doc = nlohmann::json::parse(file);
    ASSERT_EQ(doc["scenes"].size(), 1u);
    const nlohmann::json& s = doc["scenes"][0];
    EXPECT_EQ(s["name"], "ball");
    EXPECT_EQ(s["truth"]["frames_rendered"], 3);
    EXPECT_EQ(s["truth"]["self_psnr_db"], "inf");
    // Both ladders, every configuration over the three frames, errors finite and sane.
    int reference = 0, multiphase = 0;
    for (const auto& c : s["configs"]) {
        (c["mode"] == "reference" ? reference : multiphase) += 1;
        ASSERT_EQ(c["frames"].size(), 3u) << c["label"];
        EXPECT_TRUE(c["frames"][0]["temporal_rmse"].is_null());
        EXPECT_GE(c["frames"][1]["temporal_rmse"].get<double>(), 0.0);
        const double psnr = psnrValue(c["psnr_db"]);
        EXPECT_GT(psnr, 15.0) << c["label"];
        EXPECT_LT(psnr, 80.0) << c["label"];
        EXPECT_GE(c["sequence_seconds"].get<double>(), c["static_seconds"].get<double>());
        EXPECT_EQ(c["nonfinite_samples"], 0);
    }
    EXPECT_EQ(reference, 4);
    EXPECT_GE(multiphase, 5);
    // More samples make the reference more accurate: 1 spp is well below 8 spp.
    double ref1 = 0, ref8 = 0;
    for (const auto& c : s["configs"]) {
        if (c["mode"] != "reference") continue;
        const int spp = c["settings"]["samples_per_pixel"];
        if (spp == 1) ref1 = psnrValue(c["psnr_db"]);
        if (spp == 8) ref8 = psnrValue(c["psnr_db"]);
    }
    EXPECT_GT(ref8, ref1 + 3.0);
    // Each front is monotone: slower only if more accurate.
    for (const char* mode : {"reference", "multiphase"}) {
        const auto& front = s["pareto"][mode];
        ASSERT_GE(front.size(), 1u) << mode;
        for (size_t k = 1; k < front.size(); ++k) {
            EXPECT_GT(front[k]["sequence_seconds"].get<double>(),
                      front[k - 1]["sequence_seconds"].get<double>());
            EXPECT_GT(psnrValue(front[k]["psnr_db"]), psnrValue(front[k - 1]["psnr_db"]));
        }
    }
    // A speedup needs two points on the reference's front to interpolate between; on a
    // loaded machine this tiny scene's timings can leave one (then it is null, as
    // docs/evaluation.md says).
    if (s["pareto"]["reference"].size() >= 2)
        EXPECT_GT(s["speedup_at_equal_psnr"]["default"]["sequence"].get<double>(), 0.0);
    else
        EXPECT_TRUE(s["speedup_at_equal_psnr"]["default"].is_null());
    EXPECT_TRUE(s["worst_case_overhead"]["overhead"].is_number());
    EXPECT_EQ(s["worst_case_overhead"]["cut_every_frame"]["settings"]["cut_every_frame"], true);
    std::ifstream report(out + "/report.md");
    const std::string md((std::istreambuf_iterator<char>(report)),
                         std::istreambuf_iterator<char>());
    EXPECT_NE(md.find("## ball"), std::string::npos);
    EXPECT_NE(md.find("Speed at equal PSNR"), std::string::npos);

    // A second run renders no truth frame: all three come from the cache.
    const CliRun again = mpshade(args + " --quiet");
    ASSERT_EQ(again.exitCode, 0) << again.output;
    std::ifstream file2(out + "/eval.json");
    const nlohmann::json doc2 = nlohmann::json::parse(file2);
    EXPECT_EQ(doc2["scenes"][0]["truth"]["frames_cached"], 3);
    EXPECT_EQ(doc2["scenes"][0]["truth"]["frames_rendered"], 0);
}

TEST(Cli, EvalBadInputExitsTwo) {
    const std::string out = tempDir("eval_bad");
    CliRun run = mpshade("eval tests/data/scenes/ball.json --frames 3:3 --out " + out);
    EXPECT_EQ(run.exitCode, 2);
    EXPECT_NE(run.output.find("--frames"), std::string::npos) << run.output;
    run = mpshade("eval tests/data/scenes/ball.json --truth-spp 1 --out " + out);
    EXPECT_EQ(run.exitCode, 2);
    EXPECT_NE(run.output.find("--truth-spp"), std::string::npos) << run.output;
    run = mpshade("eval tests/data/scenes/no_such.json --out " + out);
    EXPECT_EQ(run.exitCode, 2);
    EXPECT_NE(run.output.find("no_such.json"), std::string::npos) << run.output;
}

// A w x h RGBA float EXR of one colour.
void writeFlat(const std::string& path, int w, int h, const std::array<float, 4>& rgba) {
    OIIO::ImageBuf buf(OIIO::ImageSpec(w, h, 4, OIIO::TypeDesc::FLOAT));
    OIIO::ImageBufAlgo::fill(buf, {rgba.data(), 4});
    ASSERT_TRUE(buf.write(path)) << buf.geterror();
}

TEST(Cli, CompareMeasuresAndDrawsTheDifference) {
    const std::string dir = tempDir("compare");
    std::filesystem::create_directories(dir);
    // Every channel off by 0.1, except blue which is clamped to 1 in both: RGB mean
    // square error 2 * 0.01 / 3, so PSNR = 10 log10(150) = 21.76 dB.
    writeFlat(dir + "/a.exr", 8, 4, {0.5f, 0.2f, 1.5f, 1.0f});
    writeFlat(dir + "/b.exr", 8, 4, {0.4f, 0.3f, 1.2f, 1.0f});
    writeFlat(dir + "/small.exr", 4, 4, {0.4f, 0.3f, 0.2f, 1.0f});
    const CliRun run = mpshade("compare " + dir + "/a.exr " + dir + "/b.exr --json --diff " + dir +
                               "/d.exr --gain 5");
    ASSERT_EQ(run.exitCode, 0) << run.output;
    const nlohmann::json doc = nlohmann::json::parse(run.output);
    EXPECT_NEAR(doc["psnr_db"].get<double>(), 10.0 * std::log10(150.0), 1e-3);
    EXPECT_NEAR(doc["max_abs_error"].get<double>(), 0.1, 1e-6);
    OIIO::ImageBuf d(dir + "/d.exr");
    ASSERT_TRUE(d.read()) << d.geterror();
    float pixel[4];
    d.getpixel(3, 2, pixel, 4);
    EXPECT_NEAR(pixel[0], 0.5f, 1e-3f);  // 5 x 0.1, in half float
    EXPECT_NEAR(pixel[1], 0.5f, 1e-3f);
    EXPECT_NEAR(pixel[2], 0.0f, 1e-6f);
    EXPECT_EQ(pixel[3], 1.0f);
    // Different sizes, a missing file, an unwritable difference image: exit 2, named.
    CliRun bad = mpshade("compare " + dir + "/a.exr " + dir + "/small.exr");
    EXPECT_EQ(bad.exitCode, 2);
    EXPECT_NE(bad.output.find("a.exr"), std::string::npos) << bad.output;
    bad = mpshade("compare " + dir + "/missing.exr " + dir + "/b.exr");
    EXPECT_EQ(bad.exitCode, 2);
    EXPECT_NE(bad.output.find("missing.exr"), std::string::npos) << bad.output;
    bad = mpshade("compare " + dir + "/a.exr " + dir + "/b.exr --diff " + dir +
                  "/no/such/folder/d.png");
    EXPECT_EQ(bad.exitCode, 2);
    EXPECT_NE(bad.output.find("d.png"), std::string::npos) << bad.output;
    // Images are read by the OpenImageIO module: one that cannot be loaded is an error that
    // says what to set, exit 2, not a crash.
    ::setenv("MPSHADE_OIIO_PLUGIN", (dir + "/no_such_module.so").c_str(), 1);
    bad = mpshade("compare " + dir + "/a.exr " + dir + "/b.exr");
    ::unsetenv("MPSHADE_OIIO_PLUGIN");
    EXPECT_EQ(bad.exitCode, 2);
    EXPECT_NE(bad.output.find("MPSHADE_OIIO_PLUGIN"), std::string::npos) << bad.output;
    EXPECT_NE(bad.output.find("no_such_module.so"), std::string::npos) << bad.output;
}

TEST(Cli, AFrameThatCannotBeWrittenNamesItsFileAndWhy) {
    // A folder where frame 0's EXR goes: the finished image cannot be moved into place.
    const std::string out = tempDir("blocked");
    std::filesystem::create_directories(out + "/frame_0000.exr/inside");
    const CliRun run =
        mpshade("render examples/teapot/scene.json --frames 0:1 --size 16x12 --quiet --out " + out);
    EXPECT_EQ(run.exitCode, 1) << run.output;
    EXPECT_NE(run.output.find("frame_0000.exr"), std::string::npos) << run.output;
    // The reason the rename failed (Linux: EISDIR), not the removal after it.
    EXPECT_NE(run.output.find(std::strerror(EISDIR)), std::string::npos) << run.output;
    for (const auto& entry : std::filesystem::directory_iterator(out))
        EXPECT_EQ(entry.path().filename().string().find("partial"), std::string::npos)
            << entry.path();
}

TEST(Cli, SppAndSeedOverrideTheScene) {
    const std::string out = tempDir("spp");
    const CliRun run = mpshade(
        "render examples/teapot/scene.json --frames 5 --size 40x30 --spp 2 --seed 3 --out " + out);
    ASSERT_EQ(run.exitCode, 0) << run.output;
    EXPECT_TRUE(std::filesystem::exists(out + "/frame_0005.exr"));
    std::ifstream statsFile(out + "/stats.json");
    const nlohmann::json stats = nlohmann::json::parse(statsFile);
    EXPECT_EQ(stats["frames"][0]["samples"], 40 * 30 * 2);
    EXPECT_EQ(stats["seed"], 3);
    EXPECT_EQ(stats["mode"], "multiphase") << "multi-phase is the default mode";
    EXPECT_GT(stats["memory_limit_mb"], 0);
    EXPECT_GT(stats["peak_resident_mb"], 0);
    EXPECT_LE(stats["peak_resident_mb"], stats["memory_limit_mb"]);
    // Making the renderer (factoring, compiling, planning) takes time no frame counts.
    EXPECT_GT(stats["setup_seconds"].get<double>(), 0.0);
    EXPECT_LT(stats["setup_seconds"].get<double>(), 60.0);
}

struct BadRun {
    const char* args;
    const char* expected;  // the start of the output
};

TEST(Cli, BadInputExitsTwoNamingThePlace) {
    const BadRun cases[] = {
        {"render tests/data/bad_scenes/negative_radius.json --out /tmp/x",
         "mpshade: tests/data/bad_scenes/negative_radius.json: objects[0].geometry.radius: error: "
         "expected a positive number, found -1\n"},
        {"render tests/data/bad_scenes/syntax_error.json --out /tmp/x",
         "mpshade: tests/data/bad_scenes/syntax_error.json:2:30: error: invalid JSON"},
        {"render tests/data/bad_scenes/bad_shader.json --out /tmp/x",
         "mpshade: tests/data/bad_shaders/missing_semicolon.sl:3:5: error: expected ';' after the "
         "statement, found 'Ci'"},
        {"render tests/data/bad_scenes/malformed_obj.json --out /tmp/x",
         "mpshade: tests/data/meshes/bad_number.obj:2:7: error: expected a number, found 'zero'"},
        {"render examples/vase/scene.json --frames 0:999 --out /tmp/x",
         "mpshade: --frames: error: the range 0:999 goes past the scene's 48 frames (0:48)\n"},
        {"render examples/vase/scene.json --frames 3:3 --out /tmp/x",
         "mpshade: --frames: error: the range 3:3 is empty"},
        {"render examples/vase/scene.json --frames a:b --out /tmp/x",
         "mpshade: --frames: error: expected A:B with whole numbers, found 'a:b'\n"},
        {"render examples/vase/scene.json --size 0x10 --out /tmp/x",
         "mpshade: --size: error: expected WxH with each in 1..16384, found '0x10'\n"},
        {"render examples/vase/scene.json --mode fast --out /tmp/x",
         "mpshade: --mode: error: unknown mode 'fast' (available: reference, multiphase)\n"},
        {"render examples/vase/scene.json --spp 0 --out /tmp/x",
         "mpshade: --spp: error: expected 1..1024, found 0\n"},
        {"render nowhere.json --out /tmp/x",
         "mpshade: nowhere.json: error: cannot open scene file\n"},
        {"render examples/vase/scene.json", "mpshade: error: --out is required"},
        // 16384^2 pixels at 1024 samples: refused by the estimate before any allocation.
        {"render examples/vase/scene.json --size 16384x16384 --spp 1024 --out /tmp/x",
         "mpshade: --size/--spp: error: 16384x16384 pixels at 1024 samples (multiphase) needs "
         "about 742"},
        {"render examples/vase/scene.json --memory-mb 100 --out /tmp/x",
         "mpshade: examples/vase/scene.json: settings: error: 480x270 pixels at 4 samples "
         "(multiphase) needs about 0.5 GB, over the memory limit of 0.1 GB (--memory-mb)"},
        {"render examples/vase/scene.json --memory-mb -5 --out /tmp/x",
         "mpshade: --memory-mb: error: expected a positive number of MB\n"},
        {"render examples/vase/scene.json --footprint-scale 9 --out /tmp/x",
         "mpshade: --footprint-scale: error: expected 0.05..8, found 9"},
        {"render examples/vase/scene.json --footprint-scale nan --out /tmp/x",
         "mpshade: --footprint-scale: error: expected 0.05..8, found"},
        {"render examples/vase/scene.json --view-lookahead -1 --out /tmp/x",
         "mpshade: --view-lookahead: error: expected 0..1000 frames, found -1"},
        {"paint", "mpshade: error: "},
    };
    for (const BadRun& c : cases) {
        const CliRun run = mpshade(c.args);
        EXPECT_EQ(run.exitCode, 2) << c.args << "\n" << run.output;
        EXPECT_EQ(run.output.rfind(c.expected, 0), 0u) << c.args << "\n" << run.output;
    }
}

TEST(Cli, EveryBadSceneExitsTwo) {
    int count = 0;
    for (const auto& entry :
         std::filesystem::directory_iterator(MPSHADE_SOURCE_DIR "/tests/data/bad_scenes")) {
        const std::string rel = "tests/data/bad_scenes/" + entry.path().filename().string();
        const CliRun run = mpshade("render " + rel + " --out " + tempDir("bad"));
        EXPECT_EQ(run.exitCode, 2) << rel << "\n" << run.output;
        EXPECT_NE(run.output.find(": error: "), std::string::npos) << run.output;
        EXPECT_EQ(run.output.find("internal error"), std::string::npos) << run.output;
        ++count;
    }
    EXPECT_GT(count, 20);
}

TEST(Cli, CtrlCKeepsEveryFinishedFrameAndValidStats) {
    // Ctrl-C once the first frame is out: the render stops after the frame under way with
    // status 130, stats.json lists exactly the frames on disk, and no partial file is left.
    const std::string out = tempDir("interrupt");
    const std::string script = ::testing::TempDir() + "mpshade_interrupt.sh";
    std::ofstream(script) << "set -m\n"  // job control: the background job keeps SIGINT
                          << "cd '" MPSHADE_SOURCE_DIR "'\n'" MPSHADE_BINARY
                          << "' render examples/courtyard/scene.json --size 160x90 --quiet --out "
                          << out << " &\npid=$!\n"
                          << "for i in $(seq 1000); do [ -f " << out
                          << "/stats.json ] && break; sleep 0.02; done\n"
                          << "kill -INT $pid\nwait $pid\necho \"rc=$?\"\n";
    FILE* pipe = popen(("bash " + script + " 2>&1").c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    std::string output;
    std::array<char, 4096> buffer;
    while (fgets(buffer.data(), buffer.size(), pipe)) output += buffer.data();
    pclose(pipe);
    EXPECT_NE(output.find("rc=130"), std::string::npos) << output;
    EXPECT_NE(output.find("stopping after this frame"), std::string::npos) << output;
    std::ifstream statsFile(out + "/stats.json");
    const nlohmann::json stats = nlohmann::json::parse(statsFile);
    const size_t written = stats["frames"].size();
    EXPECT_GE(written, 1u);
    EXPECT_LT(written, static_cast<size_t>(stats["frames_requested"]));
    size_t exrs = 0;
    for (const auto& entry : std::filesystem::directory_iterator(out)) {
        const std::string name = entry.path().filename().string();
        EXPECT_EQ(name.find("partial"), std::string::npos) << name;
        if (entry.path().extension() == ".exr") ++exrs;
    }
    EXPECT_EQ(exrs, written);
    for (const auto& f : stats["frames"]) {
        char name[32];
        std::snprintf(name, sizeof name, "/frame_%04d.png", f["index"].get<int>());
        EXPECT_TRUE(std::filesystem::exists(out + name)) << name;
    }
}

TEST(Cli, AnOutputPathThatIsAFileIsABadPath) {
    const std::string dir = tempDir("notafolder");
    std::filesystem::create_directories(dir);
    std::ofstream(dir + "/file") << "x";
    const CliRun run = mpshade("render examples/vase/scene.json --frames 0 --out " + dir + "/file");
    EXPECT_EQ(run.exitCode, 2) << run.output;
    EXPECT_EQ(
        run.output.rfind("mpshade: " + dir + "/file: error: cannot create the output folder", 0),
        0u)
        << run.output;
}

TEST(Cli, AbsurdButAcceptedNumbersRenderFinite) {
    // Finite values far outside any sensible range that the scene format accepts: an fps
    // of 1e-30 (one frame), a light of intensity 1e30 (radiance beyond half floats: written
    // as 65504), a near plane of 1e-30 and a far one of 1e30. Both modes, frames finite.
    const std::string dir = tempDir("absurd");
    std::filesystem::create_directories(dir);
    std::ofstream(dir + "/scene.json")
        << R"({"settings": {"width": 16, "height": 12, "fps": 1e-30, "duration": 1},
  "camera": {"eye": [0, 0, 4], "target": [0, 0, 0], "near": 1e-30, "far": 1e30},
  "lights": [{"type": "point", "position": [1, 2, 3], "intensity": 1e30}],
  "shaders": {"p": ")" MPSHADE_SOURCE_DIR R"(/examples/shaders/plastic.sl"},
  "objects": [{"name": "ball", "geometry": {"type": "sphere", "radius": 1}, "shader": "p"}]})";
    for (const char* mode : {"multiphase", "reference"}) {
        const std::string out = dir + "/" + mode;
        const CliRun run = mpshade("render " + dir + "/scene.json --quiet --mode " +
                                   std::string(mode) + " --out " + out);
        ASSERT_EQ(run.exitCode, 0) << run.output;
        std::ifstream statsFile(out + "/stats.json");
        const nlohmann::json stats = nlohmann::json::parse(statsFile);
        EXPECT_EQ(stats["frames"].size(), 1u);
        OIIO::ImageBuf image(out + "/frame_0000.exr");
        ASSERT_TRUE(image.read(0, 0, true, OIIO::TypeDesc::FLOAT)) << image.geterror();
        const auto pcs = OIIO::ImageBufAlgo::computePixelStats(image);
        float brightest = 0.0f;
        for (int c = 0; c < 3; ++c) {
            EXPECT_EQ(pcs.nancount[c], 0u) << mode;
            EXPECT_EQ(pcs.infcount[c], 0u) << mode;
            brightest = std::max(brightest, pcs.max[c]);
        }
        EXPECT_EQ(brightest, 65504.0f) << mode << ": the lit side saturates the half range";
    }
}

TEST(Cli, ManyDistinctShapesAreRefusedBeforeTheirRayScenesAreBuilt) {
    // 4,000 spheres of different radii: the reference would build a 2 MB ray scene for each
    // (8 GB), refused under a 2 GB limit naming the objects; multi-phase, which traces rays
    // only for shaders that cast occlusion, renders it within the same limit.
    const std::string dir = tempDir("many");
    std::filesystem::create_directories(dir);
    std::ofstream scene(dir + "/scene.json");
    scene << R"({"settings": {"width": 16, "height": 12, "duration": 0.1},
      "camera": {"eye": [0, 0, 5], "target": [0, 0, 0]},
      "shaders": {"p": ")" MPSHADE_SOURCE_DIR R"(/examples/shaders/plastic.sl"}, "objects": [)";
    for (int i = 0; i < 4000; ++i)
        scene << (i ? "," : "") << R"({"name": "s)" << i
              << R"(", "shader": "p", "geometry": {"type": "sphere", "radius": )" << 0.01 + i * 1e-5
              << R"(}, "transform": {"translate": [)" << (i % 64) / 32.0 - 1 << ", "
              << (i / 64) / 32.0 - 1 << ", 0]}}";
    scene << "]}";
    scene.close();
    const CliRun ref = mpshade(
        "render " + dir + "/scene.json --mode reference --memory-mb 2000 --out " + dir + "/ref");
    EXPECT_EQ(ref.exitCode, 2) << ref.output;
    EXPECT_NE(ref.output.find("scene.json: objects: error: 16x12 pixels at 4 samples (reference) "
                              "and the ray queries of 4000 objects needs about 8."),
              std::string::npos)
        << ref.output;
    const CliRun multi =
        mpshade("render " + dir + "/scene.json --memory-mb 2000 --quiet --out " + dir + "/mp");
    EXPECT_EQ(multi.exitCode, 0) << multi.output;
}

TEST(Cli, ProfileWritesTheCostsAndATraceThatOpens) {
    const std::string out = tempDir("profile");
    const CliRun run =
        mpshade("profile examples/vase/scene.json --frames 2:4 --size 96x54 --out " + out);
    ASSERT_EQ(run.exitCode, 0) << run.output;
    EXPECT_NE(run.output.find("profile.md"), std::string::npos) << run.output;
    std::ifstream md(out + "/profile.md");
    const std::string text((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
    for (const char* row :
         {"| vase | shadermap (half) |", "| floor | shadermap (half) |", "| 2 |", "| 3 |"})
        EXPECT_NE(text.find(row), std::string::npos) << row << "\n" << text;
    std::ifstream traceFile(out + "/trace.json");
    const nlohmann::json trace = nlohmann::json::parse(traceFile);
    ASSERT_TRUE(trace["traceEvents"].is_array());
    std::map<std::string, int> phaseSpans;
    std::set<int> threadTracks;
    for (const nlohmann::json& e : trace["traceEvents"]) {
        if (e["ph"] != "X") continue;
        EXPECT_GE(e["dur"].get<double>(), 0.0);
        if (e["pid"] == 1) ++phaseSpans[e["name"].get<std::string>()];
        if (e["pid"] == 2) threadTracks.insert(e["tid"].get<int>());
    }
    EXPECT_EQ(phaseSpans["frame"], 2);
    EXPECT_EQ(phaseSpans["static phase"], 1);  // the first frame builds both objects
    EXPECT_EQ(phaseSpans["resolve"], 2);
    EXPECT_GE(phaseSpans["shade"], 2);
    EXPECT_FALSE(threadTracks.empty());

    const CliRun bad = mpshade("profile examples/vase/scene.json --frames 40:50 --out " + out);
    EXPECT_EQ(bad.exitCode, 2) << bad.output;
    EXPECT_NE(bad.output.find("--frames"), std::string::npos) << bad.output;
    const CliRun badSpp = mpshade("profile examples/vase/scene.json --spp 0 --out " + out);
    EXPECT_EQ(badSpp.exitCode, 2) << badSpp.output;
    EXPECT_NE(badSpp.output.find("--spp"), std::string::npos) << badSpp.output;
}

TEST(Cli, PlayReportsEveryFramesDeadlineAndWritesFramesUnlessAsked) {
    const std::string out = tempDir("play");
    const CliRun run = mpshade(
        "play examples/teapot/scene.json --fps 24 --frames 0:3 --size "
        "96x54 --cache-mb 8 --out " +
        out);
    ASSERT_EQ(run.exitCode, 0) << run.output;
    EXPECT_NE(run.output.find("within 1/24 s"), std::string::npos) << run.output;
    std::ifstream statsFile(out + "/stats.json");
    const nlohmann::json stats = nlohmann::json::parse(statsFile);
    EXPECT_EQ(stats["mode"], "play");
    EXPECT_EQ(stats["cache_mb"], 8);
    ASSERT_EQ(stats["frames"].size(), 3u);
    // The regulator's ladder, as the pre-roll measured it: every frame's step is one of
    // it, and its frame counts add up to the frames played. The summary names the steps.
    const nlohmann::json& steps = stats["steps"];
    ASSERT_GE(steps.size(), 2u);
    int stepFrames = 0;
    for (size_t k = 0; k < steps.size(); ++k) {
        EXPECT_EQ(steps[k]["level"].get<size_t>(), k);
        EXPECT_GT(steps[k]["preroll_dynamic_seconds"].get<double>(), 0.0);
        stepFrames += steps[k]["frames"].get<int>();
    }
    EXPECT_EQ(stepFrames, 3);
    for (const nlohmann::json& f : stats["frames"]) {
        const nlohmann::json& step = steps[f["quality"]["level"].get<size_t>()];
        EXPECT_EQ(step["shading_rate"], f["quality"]["shading_rate"]);
        EXPECT_EQ(step["samples_per_pixel"], f["quality"]["samples_per_pixel"]);
        EXPECT_EQ(step["footprint_scale"], f["quality"]["footprint_scale"]);
    }
    EXPECT_NE(run.output.find("per sample, 4 spp"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("median frame:"), std::string::npos) << run.output;
    int met = 0;
    for (const nlohmann::json& f : stats["frames"]) {
        ASSERT_TRUE(f["deadline_met"].is_boolean());
        met += f["deadline_met"].get<bool>() ? 1 : 0;
        EXPECT_NEAR(f["budget_seconds"].get<double>(), 1.0 / 24.0, 1e-12);
        EXPECT_EQ(f["deadline_met"].get<bool>(),
                  f["wall_seconds"].get<double>() <= f["budget_seconds"].get<double>());
        EXPECT_TRUE(f["quality"]["shading_rate"].is_string());
        EXPECT_GE(f["quality"]["level"].get<int>(), 0);
        EXPECT_GT(f["quality"]["footprint_scale"].get<double>(), 0.0);
        EXPECT_TRUE(f["deferred"]["tiles"].is_number());
        const nlohmann::json& p = f["prefetch"];
        EXPECT_LE(p["filled"].get<uint64_t>(),
                  p["predicted"].get<uint64_t>() + p["adjacent"].get<uint64_t>());
        EXPECT_GE(p["seconds"].get<double>(), 0.0);
        EXPECT_TRUE(p["abandoned"].is_boolean());
        // The background filler's work since the last frame: what it filled was deferred.
        const nlohmann::json& b = f["background"];
        EXPECT_TRUE(b["filled"].is_number() && b["evicted"].is_number());
        EXPECT_GE(b["seconds"].get<double>(), 0.0);
        EXPECT_GT(f["controller_seconds"].get<double>(), 0.0);
        EXPECT_LT(f["controller_seconds"].get<double>(), f["wall_seconds"].get<double>());
        EXPECT_EQ(f["probe_hits"].get<uint64_t>() + f["quality"]["probe_fallbacks"].get<uint64_t>(),
                  f["quality"]["probes"].get<uint64_t>());
        EXPECT_LE(f["resident_bytes"].get<double>(), 8.0 * 1024 * 1024);
    }
    EXPECT_EQ(stats["deadlines_met"], met);
    EXPECT_EQ(stats["background_fills"], true);
    for (int k = 0; k < 3; ++k)
        EXPECT_TRUE(std::filesystem::exists(out + fmt::format("/frame_{:04d}.exr", k)));

    const std::string quiet = tempDir("play_no_write");
    const CliRun noWrite = mpshade(
        "play examples/teapot/scene.json --frames 0:2 --size 96x54 "
        "--no-write --no-background-fills --quiet --out " +
        quiet);
    ASSERT_EQ(noWrite.exitCode, 0) << noWrite.output;
    EXPECT_EQ(noWrite.output, "");
    EXPECT_TRUE(std::filesystem::exists(quiet + "/stats.json"));
    EXPECT_FALSE(std::filesystem::exists(quiet + "/frame_0000.exr"));
    std::ifstream quietStats(quiet + "/stats.json");
    const nlohmann::json q = nlohmann::json::parse(quietStats);
    EXPECT_EQ(q["background_fills"], false);
    for (const nlohmann::json& f : q["frames"]) EXPECT_EQ(f["background"]["filled"], 0);

    for (const char* bad : {"--fps 0", "--fps -3", "--cache-mb 0", "--spp 0"}) {
        const CliRun r =
            mpshade(std::string("play examples/teapot/scene.json ") + bad + " --out " + quiet);
        EXPECT_EQ(r.exitCode, 2) << bad << ": " << r.output;
        const std::string option = std::string(bad).substr(0, std::string(bad).find(' '));
        EXPECT_NE(r.output.find(option), std::string::npos) << r.output;
    }
}

TEST(Cli, HelpAndVersion) {
    EXPECT_EQ(mpshade("--version").exitCode, 0);
    const CliRun help = mpshade("render --help");
    EXPECT_EQ(help.exitCode, 0);
    EXPECT_NE(help.output.find("--frames"), std::string::npos);
}

}  // namespace
