// The shader-map store from the command line: a second run fills nothing and renders the
// same bits; what no static part reads keeps every stored tile; a damaged tile is refilled
// and reported; concurrent renders share one store; bake, store info, gc and export; the
// batch contract (--skip-existing, --shard-stats, --threads).
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <future>
#include <vector>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_support.h"

namespace {

namespace fs = std::filesystem;
using mpshade::cli::CliRun;
using mpshade::cli::mpshade;
using mpshade::cli::tempDir;

const std::string kSmall = " --size 96x54 --no-single-phase --quiet";

nlohmann::json readJson(const fs::path& file) {
    std::ifstream in(file);
    return nlohmann::json::parse(in);
}

std::vector<float> pixels(const std::string& file) {
    OIIO::ImageBuf image(file);
    EXPECT_TRUE(image.read()) << image.geterror();
    std::vector<float> v(static_cast<size_t>(image.spec().image_pixels()) * 4);
    image.get_pixels(image.roi(), OIIO::TypeDesc::FLOAT, v.data());
    return v;
}

uint64_t sum(const nlohmann::json& frames, const char* key) {
    uint64_t total = 0;
    for (const auto& f : frames) total += f[key].get<uint64_t>();
    return total;
}

// The vase scene written to `dir` with its files named absolutely, after `edit`.
std::string vaseVariant(const std::string& dir, const std::function<void(nlohmann::json&)>& edit) {
    nlohmann::json scene = readJson(MPSHADE_SOURCE_DIR "/examples/vase/scene.json");
    scene["shaders"]["marble"] = MPSHADE_SOURCE_DIR "/examples/shaders/marble.sl";
    scene["shaders"]["wood"] = MPSHADE_SOURCE_DIR "/examples/shaders/wood.sl";
    scene["objects"][0]["geometry"]["file"] = MPSHADE_SOURCE_DIR "/examples/vase/meshes/vase.obj";
    edit(scene);
    fs::create_directories(dir);
    const std::string path = dir + "/scene.json";
    std::ofstream(path) << scene.dump(2);
    return path;
}

TEST(CliStore, ASecondRenderReadsEveryTileAndRendersTheSameBits) {
    const std::string store = tempDir("store_twice"), a = tempDir("store_a"),
                      b = tempDir("store_b");
    const std::string args =
        "render examples/vase/scene.json --frames 0:3" + kSmall + " --store " + store;
    ASSERT_EQ(mpshade(args + " --out " + a).exitCode, 0);
    const CliRun second = mpshade(args + " --out " + b);
    ASSERT_EQ(second.exitCode, 0) << second.output;
    const nlohmann::json first = readJson(a + "/stats.json"), again = readJson(b + "/stats.json");
    const uint64_t filled = sum(first["frames"], "tiles_filled");
    EXPECT_GT(filled, 100u);
    EXPECT_EQ(first["store"]["tiles_written"].get<uint64_t>(), filled);
    EXPECT_EQ(sum(again["frames"], "tiles_filled"), 0u);
    EXPECT_EQ(sum(again["frames"], "tiles_from_store"), filled);
    // Each representation's facets were read, not diced again.
    EXPECT_EQ(sum(first["frames"], "static_runs_from_store"), 0u);
    EXPECT_EQ(sum(again["frames"], "static_runs_from_store"), sum(again["frames"], "static_runs"));
    EXPECT_GT(sum(again["frames"], "static_runs"), 0u);
    // Nothing was made again: no facets, no survey of them (the records are all read).
    EXPECT_GT(first["store"]["records_written"].get<uint64_t>(), 0u);
    EXPECT_EQ(again["store"]["records_written"], 0);
    EXPECT_EQ(again["store"]["records_read"], first["store"]["records_written"]);
    EXPECT_EQ(again["store"]["tiles_read"].get<uint64_t>(), filled);
    for (size_t i = 0; i < first["objects"].size(); ++i)
        EXPECT_EQ(again["objects"][i]["tiles_from_store"], first["objects"][i]["tiles_filled"]);
    for (const char* frame : {"frame_0000.exr", "frame_0001.exr", "frame_0002.exr"})
        EXPECT_EQ(pixels(a + "/" + frame), pixels(b + "/" + frame)) << frame;
}

TEST(CliStore, TheCameraKeepsEveryStoredMapAStaticParameterRefillsOnlyItsObject) {
    const std::string store = tempDir("store_edits"), dir = tempDir("store_edits_scenes");
    const std::string base = vaseVariant(dir + "/base", [](nlohmann::json&) {});
    const std::string moved = vaseVariant(dir + "/moved", [](nlohmann::json& s) {
        s["camera"]["keys"][0]["eye"] = {0.3, 2.3, 5.8};
    });
    const std::string rings = vaseVariant(dir + "/rings", [](nlohmann::json& s) {
        s["objects"][1]["params"] = {{"ringScale", 5.0}};
    });
    const std::string opts = " --frames 0:1" + kSmall + " --store " + store + " --out ";
    ASSERT_EQ(mpshade("render " + base + opts + dir + "/o1").exitCode, 0);
    const auto maps = [&] {
        const CliRun info = mpshade("store info --json --store " + store);
        EXPECT_EQ(info.exitCode, 0) << info.output;
        return nlohmann::json::parse(info.output)["maps"];
    };
    ASSERT_EQ(maps().size(), 2u);
    // The view is read by no static part: the same two maps, most of the tiles found.
    ASSERT_EQ(mpshade("render " + moved + opts + dir + "/o2").exitCode, 0);
    EXPECT_EQ(maps().size(), 2u);
    const nlohmann::json m = readJson(dir + "/o2/stats.json");
    EXPECT_GT(m["objects"][0]["tiles_from_store"].get<uint64_t>(), 0u);
    // ... and what it reads is what this view needs: the bits of a render without a store
    // (facets diced for the first view would not be).
    ASSERT_EQ(mpshade("render " + moved + " --frames 0:1" + kSmall + " --no-store --out " + dir +
                      "/o2alone")
                  .exitCode,
              0);
    EXPECT_EQ(pixels(dir + "/o2/frame_0000.exr"), pixels(dir + "/o2alone/frame_0000.exr"));
    // The floor's ring scale is folded into its static part: a new map for the floor only;
    // the vase reads every tile it needs.
    ASSERT_EQ(mpshade("render " + rings + opts + dir + "/o3").exitCode, 0);
    const nlohmann::json all = maps();
    ASSERT_EQ(all.size(), 3u);
    int floors = 0;
    for (const auto& map : all) floors += map["object"] == "floor" ? 1 : 0;
    EXPECT_EQ(floors, 2);
    // The floor's size is its geometry: another map of the floor again.
    const std::string wider = vaseVariant(dir + "/wider", [](nlohmann::json& s) {
        s["objects"][1]["params"] = {{"ringScale", 5.0}};
        s["objects"][1]["geometry"]["size"] = {14, 14};
    });
    ASSERT_EQ(mpshade("render " + wider + opts + dir + "/o4").exitCode, 0);
    EXPECT_EQ(maps().size(), 4u);
    const nlohmann::json r = readJson(dir + "/o3/stats.json");
    EXPECT_EQ(r["objects"][0]["name"], "vase");
    EXPECT_EQ(r["objects"][0]["tiles_filled"], 0);
    EXPECT_GT(r["objects"][0]["tiles_from_store"].get<uint64_t>(), 0u);
    EXPECT_GT(r["objects"][1]["tiles_filled"].get<uint64_t>(), 0u);
    EXPECT_EQ(r["objects"][1]["tiles_from_store"], 0);
}

TEST(CliStore, ADamagedTileIsFilledAgainAndReportedNeverRead) {
    const std::string store = tempDir("store_damaged"), a = tempDir("store_d1"),
                      b = tempDir("store_d2");
    const std::string args =
        "render examples/vase/scene.json --frames 0:1" + kSmall + " --store " + store;
    ASSERT_EQ(mpshade(args + " --out " + a).exitCode, 0);
    // The first three tiles of the largest pack damaged in place (a disk error): each fails
    // its checksum. A pack is tiles one after another, each a 48-byte header (its payload's
    // size at byte 32) and its payload.
    fs::path largest;
    for (const auto& e : fs::recursive_directory_iterator(store))
        if (e.path().extension() == ".pack" &&
            (largest.empty() || fs::file_size(e.path()) > fs::file_size(largest)))
            largest = e.path();
    ASSERT_FALSE(largest.empty());
    {
        std::fstream f(largest, std::ios::in | std::ios::out | std::ios::binary);
        uint64_t payload = 0;
        f.seekg(32);
        f.read(reinterpret_cast<char*>(&payload), sizeof payload);
        for (uint64_t k = 0; k < 3; ++k) {
            const auto at = static_cast<std::streamoff>(k * (48 + payload) + 48 + 10);
            f.seekg(at);
            const char c = static_cast<char>(f.get());
            f.seekp(at);
            f.put(static_cast<char>(c ^ 0x5a));
        }
    }
    const CliRun run =
        mpshade(args.substr(0, args.find(" --quiet")) + " --store " + store + " --out " + b);
    ASSERT_EQ(run.exitCode, 0) << run.output;
    EXPECT_NE(run.output.find("3 damaged tile(s)"), std::string::npos) << run.output;
    const nlohmann::json stats = readJson(b + "/stats.json");
    EXPECT_EQ(stats["store"]["tiles_damaged"], 3);
    EXPECT_EQ(sum(stats["frames"], "tiles_filled"), 3u);
    EXPECT_EQ(pixels(a + "/frame_0000.exr"), pixels(b + "/frame_0000.exr"));
}

TEST(CliStore, TwoRendersAtOnceShareOneStoreAndFillEachTileOnce) {
    const std::string store = tempDir("store_shared"), out = tempDir("store_shared_out"),
                      alone = tempDir("store_alone"), aloneStore = tempDir("store_alone_store");
    // The gallery: its first frame's fills take long enough for both to be filling at once.
    const std::string args =
        "render examples/gallery/scene.json --frames 0:3 --size 160x90 "
        "--no-single-phase --quiet";
    auto one = std::async(std::launch::async, [&] {
        return mpshade(args + " --store " + store + " --shard-stats --out " + out);
    });
    auto two = std::async(std::launch::async,
                          [&] { return mpshade(args + " --store " + store + " --out " + out); });
    const CliRun r1 = one.get(), r2 = two.get();
    ASSERT_EQ(r1.exitCode, 0) << r1.output;
    ASSERT_EQ(r2.exitCode, 0) << r2.output;
    for (const auto& e : fs::directory_iterator(out))
        EXPECT_EQ(e.path().filename().string().find("partial"), std::string::npos) << e.path();
    // Alone, with a store of its own: the tiles the frames need.
    ASSERT_EQ(mpshade(args + " --store " + aloneStore + " --out " + alone).exitCode, 0);
    const uint64_t needed = sum(readJson(alone + "/stats.json")["frames"], "tiles_filled");
    const uint64_t filled = sum(readJson(out + "/stats_0000_0003.json")["frames"], "tiles_filled") +
                            sum(readJson(out + "/stats.json")["frames"], "tiles_filled");
    EXPECT_GT(needed, 0u);
    EXPECT_EQ(filled, needed);  // each tile filled once, by one of the two
    for (const char* frame : {"/frame_0000.exr", "/frame_0002.exr"})
        EXPECT_EQ(pixels(out + frame), pixels(alone + frame)) << frame;
}

TEST(CliStore, BakeFillsWhatARenderThenReads) {
    const std::string store = tempDir("store_bake"), out = tempDir("store_bake_out");
    const CliRun bake =
        mpshade("bake examples/vase/scene.json --frames 0:2 --size 96x54 --store " + store);
    ASSERT_EQ(bake.exitCode, 0) << bake.output;
    EXPECT_NE(bake.output.find("bake: frame 1 (2 of 2)"), std::string::npos) << bake.output;
    EXPECT_NE(bake.output.find("floor"), std::string::npos) << bake.output;
    ASSERT_EQ(mpshade("render examples/vase/scene.json --frames 0:2" + kSmall + " --store " +
                      store + " --out " + out)
                  .exitCode,
              0);
    const nlohmann::json stats = readJson(out + "/stats.json");
    EXPECT_EQ(sum(stats["frames"], "tiles_filled"), 0u);
    EXPECT_GT(sum(stats["frames"], "tiles_from_store"), 0u);
    EXPECT_EQ(mpshade("bake examples/vase/scene.json --no-store").exitCode, 2);
}

TEST(CliStore, InfoGcAndExport) {
    const std::string store = tempDir("store_tools"), out = tempDir("store_export");
    ASSERT_EQ(
        mpshade("bake examples/vase/scene.json --frames 0:1 --size 96x54 --quiet --store " + store)
            .exitCode,
        0);
    const CliRun info = mpshade("store info --store " + store);
    ASSERT_EQ(info.exitCode, 0) << info.output;
    EXPECT_NE(info.output.find("2 map(s)"), std::string::npos) << info.output;
    EXPECT_NE(info.output.find("marble"), std::string::npos) << info.output;
    // Both filled by this build.
    const CliRun json = mpshade("store info --json --store " + store);
    ASSERT_EQ(json.exitCode, 0) << json.output;
    const nlohmann::json listed = nlohmann::json::parse(json.output);
    ASSERT_EQ(listed["maps"].size(), 2u);
    for (const nlohmann::json& m : listed["maps"]) {
        EXPECT_EQ(m["build"], "this") << m.dump();
        EXPECT_EQ(m["engine"].get<std::string>().size(), 32u) << m.dump();
    }

    const CliRun exported = mpshade("store export examples/vase/scene.json --object floor --out " +
                                    out + " --max-size 256 --store " + store);
    ASSERT_EQ(exported.exitCode, 0) << exported.output;
    OIIO::ImageBuf chart(out + "/chart_0000.exr");
    ASSERT_TRUE(chart.read()) << chart.geterror();
    EXPECT_EQ(chart.spec().width, 256);
    EXPECT_EQ(chart.nmiplevels(), 9);  // 256 .. 1
    const std::vector<std::string>& names = chart.spec().channelnames;
    EXPECT_NE(std::find(names.begin(), names.end(), "filled"), names.end());
    // Some texels filled, some not: unfilled ones are marked, not invented.
    const auto stats = OIIO::ImageBufAlgo::computePixelStats(chart);
    const int filled = chart.spec().channelindex("filled");
    EXPECT_GT(stats.avg[static_cast<size_t>(filled)], 0.0f);
    EXPECT_LT(stats.avg[static_cast<size_t>(filled)], 1.0f);
    EXPECT_EQ(mpshade("store export examples/vase/scene.json --object nobody --out " + out +
                      " --store " + store)
                  .exitCode,
              2);

    const CliRun gc = mpshade("store gc --max-mb 0 --store " + store);
    ASSERT_EQ(gc.exitCode, 0) << gc.output;
    EXPECT_NE(mpshade("store info --store " + store).output.find("0 map(s)"), std::string::npos);
}

TEST(CliStore, SkipExistingRendersOnlyTheFramesMissing) {
    const std::string out = tempDir("skip");
    const std::string args =
        "render examples/teapot/scene.json --size 64x36 --no-store --out " + out;
    ASSERT_EQ(mpshade(args + " --frames 1:2 --quiet").exitCode, 0);
    const auto written = fs::last_write_time(out + "/frame_0001.exr");
    const CliRun run = mpshade(args + " --frames 0:3 --skip-existing");
    ASSERT_EQ(run.exitCode, 0) << run.output;
    EXPECT_NE(run.output.find("1 frame(s) already in"), std::string::npos) << run.output;
    EXPECT_EQ(fs::last_write_time(out + "/frame_0001.exr"), written);
    EXPECT_TRUE(fs::exists(out + "/frame_0000.exr"));
    EXPECT_TRUE(fs::exists(out + "/frame_0002.png"));
    const nlohmann::json stats = readJson(out + "/stats.json");
    ASSERT_EQ(stats["frames"].size(), 2u);
    EXPECT_EQ(stats["frames"][1]["index"], 2);
}

TEST(CliStore, ThreadsAndStoreOptionsAreChecked) {
    const std::string out = tempDir("threads");
    const CliRun one = mpshade(
        "render examples/teapot/scene.json --frames 0:1 --size 64x36 "
        "--quiet --no-store --threads 1 --out " +
        out);
    EXPECT_EQ(one.exitCode, 0) << one.output;
    const CliRun bad = mpshade("render examples/teapot/scene.json --threads -2 --out " + out);
    EXPECT_EQ(bad.exitCode, 2);
    EXPECT_NE(bad.output.find("--threads"), std::string::npos) << bad.output;
    const std::string file = out + "/a_file";
    std::ofstream(file) << "x";
    const CliRun store = mpshade(
        "render examples/teapot/scene.json --frames 0:1 --size 64x36 "
        "--store " +
        file + " --out " + out);
    EXPECT_EQ(store.exitCode, 2);
    EXPECT_NE(store.output.find("--store"), std::string::npos) << store.output;
}

}  // namespace

namespace {

// A farm's shards: frames rendered in requests that start later, planned over the whole
// range, are the bits of one render of the range -- also when a retried shard skips frames
// already written, and with a store shared by all.
TEST(CliStore, ShardsPlannedOverTheRangeRenderTheBitsOfOneRender) {
    const std::string one = tempDir("plan_one"), shards = tempDir("plan_shards"),
                      store = tempDir("plan_store");
    const std::string args = "render examples/courtyard/scene.json --size 96x54 --quiet";
    ASSERT_EQ(mpshade(args + " --frames 0:6 --no-store --out " + one).exitCode, 0);
    ASSERT_EQ(mpshade("bake examples/courtyard/scene.json --frames 0:6 --size 96x54 --quiet "
                      "--store " +
                      store)
                  .exitCode,
              0);
    for (const char* range : {"0:2", "2:4", "4:6"}) {
        const CliRun run =
            mpshade(args + " --frames " + std::string(range) +
                    " --plan-frames 0:6 --shard-stats --store " + store + " --out " + shards);
        ASSERT_EQ(run.exitCode, 0) << run.output;
    }
    // A retried last shard whose first frame is written: rendered again, not rewritten.
    fs::remove(shards + "/frame_0005.exr");
    ASSERT_EQ(mpshade(args + " --frames 4:6 --plan-frames 0:6 --skip-existing --store " + store +
                      " --out " + shards)
                  .exitCode,
              0);
    for (int f = 0; f < 6; ++f) {
        const std::string name = fmt::format("/frame_{:04d}.exr", f);
        EXPECT_EQ(pixels(one + name), pixels(shards + name)) << name;
    }
    const nlohmann::json last = readJson(shards + "/stats_0004_0006.json");
    EXPECT_EQ(sum(last["frames"], "tiles_filled"), 0u);  // the bake filled them all
    // Without the plan, a later request builds at its own first frame: other bits (this is
    // what the plan is for; if it ever stops differing, the test above proves less).
    const std::string alone = tempDir("plan_alone");
    ASSERT_EQ(mpshade(args + " --frames 4:6 --no-store --out " + alone).exitCode, 0);
    EXPECT_NE(pixels(one + "/frame_0004.exr"), pixels(alone + "/frame_0004.exr"));
    const CliRun outside = mpshade(args + " --frames 4:6 --plan-frames 0:5 --out " + alone);
    EXPECT_EQ(outside.exitCode, 2);
    EXPECT_NE(outside.output.find("--plan-frames"), std::string::npos) << outside.output;
    const CliRun malformed = mpshade(args + " --frames 4:6 --plan-frames 0:x --out " + alone);
    EXPECT_EQ(malformed.exitCode, 2);
    EXPECT_NE(malformed.output.find("--plan-frames: error"), std::string::npos) << malformed.output;
}

}  // namespace

namespace {

// A bake killed with SIGKILL part way leaves a store later runs use without error: packs
// appear whole or not at all, and what the killed bake left half-written is never read.
TEST(CliStore, ABakeKilledPartWayLeavesAStoreLaterRunsUse) {
    const std::string store = tempDir("killed_store"), a = tempDir("killed_a"),
                      b = tempDir("killed_b");
    for (int delayMs : {150, 400}) {
        const std::string command = "cd '" MPSHADE_SOURCE_DIR "' && ('" MPSHADE_BINARY
                                    "' bake examples/gallery/scene.json "
                                    "--frames 0:6 --size 160x90 --quiet --store " +
                                    store + " & pid=$!; sleep " +
                                    fmt::format("{:.3f}", delayMs / 1000.0) +
                                    "; kill -9 $pid; wait $pid) >/dev/null 2>&1";
        ASSERT_NE(std::system(command.c_str()), -1);
    }
    const std::string args =
        "render examples/gallery/scene.json --frames 0:3 --size 160x90 "
        "--no-single-phase --quiet --out ";
    const CliRun run = mpshade(args + a + " --store " + store);
    ASSERT_EQ(run.exitCode, 0) << run.output;
    EXPECT_EQ(run.output, "");  // no warning: nothing damaged
    const nlohmann::json stats = readJson(a + "/stats.json");
    EXPECT_EQ(stats["store"]["tiles_damaged"], 0);
    ASSERT_EQ(mpshade(args + b + " --no-store").exitCode, 0);
    for (const char* frame : {"/frame_0000.exr", "/frame_0002.exr"})
        EXPECT_EQ(pixels(a + frame), pixels(b + frame)) << frame;
}

}  // namespace

namespace {

// A store whose map descriptions are damaged or hostile: info lists the maps blank, export
// refuses naming the file, neither crashes nor allocates what a description claims.
TEST(CliStore, DamagedMapDescriptionsAreReportedNotTrusted) {
    const std::string store = tempDir("hostile_store"), out = tempDir("hostile_out");
    ASSERT_EQ(
        mpshade("bake examples/vase/scene.json --frames 0:1 --size 64x36 --quiet --store " + store)
            .exitCode,
        0);
    const auto describe = [&](const std::string& text) {
        for (const auto& e : fs::directory_iterator(store + "/tiles-v1"))
            std::ofstream(e.path() / "map.json") << text;
    };
    describe(R"({"object": "floor", "shader": "wood", "channels": 5, "resolution": -3})");
    const CliRun info = mpshade("store info --store " + store);
    EXPECT_EQ(info.exitCode, 0) << info.output;
    EXPECT_NE(info.output.find("2 map(s)"), std::string::npos) << info.output;
    describe(R"({"object": "floor", "shader": "wood", "channels": ["a", "b"],)"
             R"( "resolution": 1073741824, "tile_size": 16, "border": 1})");
    const CliRun exported = mpshade("store export examples/vase/scene.json --object floor --out " +
                                    out + " --store " + store);
    EXPECT_EQ(exported.exitCode, 2) << exported.output;
    EXPECT_NE(exported.output.find("map.json"), std::string::npos) << exported.output;
    describe("{not json");
    EXPECT_EQ(mpshade("store info --store " + store).exitCode, 0);
}

}  // namespace

namespace {

// Another build never reads what this one stored: the same binary with one byte more
// (still runnable) finds nothing in the store, fills every tile itself and says why; this
// build, finding its own maps, says nothing.
TEST(CliStore, AnotherBuildReadsNothingThisOneStored) {
    const std::string store = tempDir("build_store"), a = tempDir("build_a"),
                      b = tempDir("build_b"), copy = tempDir("build_bin");
    fs::create_directories(copy);
    const std::string other = copy + "/mpshade";
    fs::copy_file(MPSHADE_BINARY, other);
    std::ofstream(other, std::ios::app | std::ios::binary) << '\n';
    const std::string args =
        " render examples/vase/scene.json --frames 0:1" + kSmall + " --store " + store + " --out ";
    const CliRun first = mpshade(args.substr(1) + a);
    ASSERT_EQ(first.exitCode, 0);
    const char* note = "map(s) of this scene's objects that another build of mpshade filled";
    EXPECT_EQ(first.output.find(note), std::string::npos) << first.output;
    const std::string command =
        "cd '" MPSHADE_SOURCE_DIR "' && '" + other + "'" + args + b + " 2>&1";
    std::string output;
    FILE* pipe = popen(command.c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    char buffer[4096];
    while (fgets(buffer, sizeof buffer, pipe)) output += buffer;
    ASSERT_EQ(pclose(pipe), 0) << output;
    // The vase and its floor: two maps of this scene's objects, each made by the first build.
    EXPECT_NE(output.find("holds 2 " + std::string(note)), std::string::npos) << output;
    // The first build again: it reads its own tiles; the other build's maps go unmentioned.
    const CliRun again = mpshade(args.substr(1) + tempDir("build_again"));
    EXPECT_EQ(again.output.find(note), std::string::npos) << again.output;
    const nlohmann::json mine = readJson(a + "/stats.json"), theirs = readJson(b + "/stats.json");
    EXPECT_GT(sum(theirs["frames"], "tiles_filled"), 0u);
    EXPECT_EQ(sum(theirs["frames"], "tiles_from_store"), 0u);
    EXPECT_EQ(sum(theirs["frames"], "static_runs_from_store"), 0u);
    EXPECT_EQ(sum(theirs["frames"], "tiles_filled"), sum(mine["frames"], "tiles_filled"));
}

}  // namespace
