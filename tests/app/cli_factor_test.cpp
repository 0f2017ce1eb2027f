// `mpshade factor` as a shader's author runs it, and the shading cost a render shows per
// pixel (`render --cost-images`).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

#include <OpenImageIO/imagebuf.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_support.h"

namespace {

using mpshade::cli::CliRun;
using mpshade::cli::mpshade;
using mpshade::cli::tempDir;

struct BadRun {
    const char* args;
    const char* expected;  // the start of the output
};

TEST(Cli, FactorShowsASmallTupleAndACheapDynamicPart) {
    const CliRun run =
        mpshade("factor examples/shaders/marble.sl --scene examples/vase/scene.json --object vase");
    ASSERT_EQ(run.exitCode, 0) << run.output;
    EXPECT_NE(run.output.find("n-tuple: 3 floats"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("dynamic lines"), std::string::npos);
    EXPECT_NE(run.output.find("I, the direction from the eye"), std::string::npos) << run.output;

    const CliRun json = mpshade(
        "factor examples/shaders/marble.sl --scene examples/vase/scene.json --object vase --json");
    ASSERT_EQ(json.exitCode, 0) << json.output;
    const nlohmann::json doc = nlohmann::json::parse(json.output);
    EXPECT_EQ(doc["chosen_width"], 3);
    EXPECT_EQ(doc["bytes_per_texel"]["float"], 12);
    EXPECT_EQ(doc["bytes_per_texel"]["half"], 6);
    EXPECT_EQ(doc["channels"].size(), 3u);
    EXPECT_EQ(doc["channels"][0]["type"], "color");
    const int staticCost = doc["cost"]["static"], dynamicCost = doc["cost"]["dynamic"];
    EXPECT_LT(dynamicCost * 10, staticCost);
    EXPECT_GT(doc["dynamic_lines"].size(), 0u);
}

TEST(Cli, FactorBindingChangesTheCut) {
    // Without a scene the shader's light is fixed; the teapot's point light moves, so its
    // diffuse light can no longer be stored.
    // Storing everything static (--store-above-cost 0) shows the cut itself.
    const nlohmann::json fixed = nlohmann::json::parse(
        mpshade("factor examples/shaders/plastic.sl --store-above-cost 0 --json").output);
    const nlohmann::json moving = nlohmann::json::parse(
        mpshade("factor examples/shaders/plastic.sl --scene examples/teapot/scene.json "
                "--object teapot --store-above-cost 0 --json")
            .output);
    EXPECT_GT(fixed["cost"]["static"].get<int>(), moving["cost"]["static"].get<int>());
    EXPECT_EQ(fixed["cost"]["static_repeated"], 0);
    // By default the teapot's three floats of fixed diffuse light (30 units) are not worth a
    // probe: nothing is stored and the dynamic part runs the whole shader.
    const CliRun byDefault = mpshade(
        "factor examples/shaders/plastic.sl --scene examples/teapot/scene.json --object teapot");
    EXPECT_NE(byDefault.output.find("nothing stored: 30 cost units of static work"),
              std::string::npos)
        << byDefault.output;
    const nlohmann::json cheap = nlohmann::json::parse(
        mpshade("factor examples/shaders/plastic.sl --scene examples/teapot/scene.json "
                "--object teapot --json")
            .output);
    EXPECT_EQ(cheap["chosen_width"], 0);
    EXPECT_EQ(cheap["cost"]["static_repeated"], moving["cost"]["static"]);
    EXPECT_EQ(cheap["cost"]["dynamic"], cheap["cost"]["unfactored"]);
}

TEST(Cli, FactorEveryObjectOrOneWithItsOwnShader) {
    // --scene alone: every object with its own shader and binding; --object without a
    // shader file: that object's; another file on an object's binding: factored, with a note.
    const CliRun all = mpshade("factor --scene examples/vase/scene.json --json");
    ASSERT_EQ(all.exitCode, 0) << all.output;
    const nlohmann::json doc = nlohmann::json::parse(all.output);
    ASSERT_EQ(doc["objects"].size(), 2u);
    EXPECT_EQ(doc["objects"][0]["object"], "vase");
    EXPECT_EQ(doc["objects"][0]["shader"], "marble");
    EXPECT_EQ(doc["objects"][1]["object"], "floor");
    EXPECT_EQ(doc["objects"][1]["shader"], "wood");
    const nlohmann::json floor = nlohmann::json::parse(
        mpshade("factor --scene examples/vase/scene.json --object floor --json").output);
    nlohmann::json second = doc["objects"][1];
    second.erase("object");
    EXPECT_EQ(floor, second);
    const CliRun whatIf = mpshade(
        "factor examples/shaders/marble.sl --scene examples/vase/scene.json --object floor");
    EXPECT_EQ(whatIf.exitCode, 0) << whatIf.output;
    EXPECT_EQ(whatIf.output.rfind("mpshade: note: object 'floor' uses ", 0), 0u) << whatIf.output;
    EXPECT_NE(whatIf.output.find("marble (examples/shaders/marble.sl), factored for object "
                                 "'floor' in examples/vase/scene.json"),
              std::string::npos)
        << whatIf.output;
}

TEST(Cli, FactorTheWholeSceneGroupsSplitsAlike) {
    // The courtyard's 51 objects: each in exactly one group; its eleven marble objects (ten
    // columns and the plinth, one shader in different colours) in one.
    const CliRun run = mpshade("factor --scene examples/courtyard/scene.json --json");
    ASSERT_EQ(run.exitCode, 0) << run.output;
    const nlohmann::json doc = nlohmann::json::parse(run.output);
    std::map<std::string, int> seen;
    for (const nlohmann::json& g : doc["splits"])
        for (const nlohmann::json& o : g["objects"]) ++seen[o.get<std::string>()];
    EXPECT_EQ(seen.size(), doc["objects"].size());
    for (const auto& [name, count] : seen) EXPECT_EQ(count, 1) << name;
    int marbleGroups = 0;
    for (const nlohmann::json& g : doc["splits"])
        if (g["shader"] == "marble") {
            ++marbleGroups;
            EXPECT_EQ(g["objects"].size(), 11u);
            EXPECT_EQ(g["bytes_per_texel"], 2 * g["channels"].get<int>());  // auto: binary16
            double bytes = 0.0;  // the group's estimate is its objects'
            for (const nlohmann::json& o : doc["objects"])
                for (const nlohmann::json& name : g["objects"])
                    if (o["object"] == name) bytes += o["map_estimate"]["bytes"].get<double>();
            EXPECT_GT(bytes, 0.0);
            EXPECT_NEAR(g["map_bytes"].get<double>(), bytes, 1e-6 * bytes);
        }
    EXPECT_EQ(marbleGroups, 1);
    EXPECT_NE(mpshade("factor --scene examples/courtyard/scene.json")
                  .output.find("the scene: 51 objects"),
              std::string::npos);
}

TEST(Cli, FactorEstimatesTheMapBytesARenderOfThatFrameFills) {
    // Each object's estimate names the frame that asks most of its map; rendering that frame
    // alone (constant quality: every tile its probes read is filled, and only those) fills
    // within a quarter of the estimate. The examples' objects are 0.78-1.24x
    // (docs/factoring.md); the vase's floor, a grazing plane, and the vase itself here.
    const CliRun run = mpshade("factor --scene examples/vase/scene.json --json");
    ASSERT_EQ(run.exitCode, 0) << run.output;
    const nlohmann::json doc = nlohmann::json::parse(run.output);
    for (const nlohmann::json& object : doc["objects"]) {
        const std::string name = object["object"];
        SCOPED_TRACE(name);
        const nlohmann::json& estimate = object["map_estimate"];
        const int channels = object["chosen_width"];
        ASSERT_GT(channels, 0);
        // The precision auto chooses, as the render's map is made.
        const int bytes = estimate["precision"] == "half" ? 2 : 4;
        EXPECT_EQ(estimate["precision"], "half");
        EXPECT_NE(estimate["precision_reason"].get<std::string>().find("half: rounding"),
                  std::string::npos);
        EXPECT_DOUBLE_EQ(estimate["bytes"].get<double>(),
                         estimate["tiles"].get<double>() * 18 * 18 * channels * bytes);
        const int frame = estimate["frame"];
        ASSERT_GE(frame, 0);
        const std::string out = tempDir("map_estimate_" + name);
        const CliRun render = mpshade(
            "render examples/vase/scene.json --no-single-phase "
            "--no-store --frames " +
            std::to_string(frame) + ":" + std::to_string(frame + 1) + " --out " + out);
        ASSERT_EQ(render.exitCode, 0) << render.output;
        std::ifstream statsFile(out + "/stats.json");
        const nlohmann::json stats = nlohmann::json::parse(statsFile);
        double filled = -1.0;
        for (const nlohmann::json& o : stats["objects"])
            if (o["name"] == name) filled = o["map_bytes"].get<double>();
        EXPECT_GT(filled, 0.75 * estimate["bytes"].get<double>());
        EXPECT_LT(filled, 1.25 * estimate["bytes"].get<double>());
    }
    const CliRun text = mpshade("factor --scene examples/vase/scene.json --object floor");
    EXPECT_NE(text.output.find("asks most: about "), std::string::npos) << text.output;

    // All the maps at once, on the courtyard (its objects' maps peak at different frames:
    // the busiest frame asks for well under their peaks' sum): the frame that asks most of
    // them together, against what a render of it alone holds resident, and the tile
    // cache's budget.
    const CliRun courtyard = mpshade("factor --scene examples/courtyard/scene.json --json");
    ASSERT_EQ(courtyard.exitCode, 0) << courtyard.output;
    const nlohmann::json all = nlohmann::json::parse(courtyard.output);
    const nlohmann::json& busiest = all["busiest_frame"];
    const int frame = busiest["frame"];
    ASSERT_GE(frame, 0);
    EXPECT_DOUBLE_EQ(busiest["cache_bytes"].get<double>(), 96.0 * 1048576);
    double peaks = 0.0;
    for (const nlohmann::json& split : all["splits"]) peaks += split["map_bytes"].get<double>();
    EXPECT_LT(busiest["map_bytes"].get<double>(), 0.8 * peaks);
    const std::string out = tempDir("map_estimate_busiest");
    const CliRun render =
        mpshade("render examples/courtyard/scene.json --no-single-phase --no-store --frames " +
                std::to_string(frame) + ":" + std::to_string(frame + 1) + " --out " + out);
    ASSERT_EQ(render.exitCode, 0) << render.output;
    std::ifstream statsFile(out + "/stats.json");
    const double resident =
        nlohmann::json::parse(statsFile)["frames"][0]["resident_bytes"].get<double>();
    EXPECT_GT(resident, 0.75 * busiest["map_bytes"].get<double>());
    EXPECT_LT(resident, 1.25 * busiest["map_bytes"].get<double>());
    const CliRun text2 = mpshade("factor --scene examples/courtyard/scene.json");
    EXPECT_NE(text2.output.find("the frame that asks most of all the maps at once: frame " +
                                std::to_string(frame)),
              std::string::npos)
        << text2.output;
}

TEST(Cli, FactorWhatIfStoreComparesWithTheSplitWithout) {
    // plastic.sl stores nothing by default (its lit colour is cheaper to repeat); --store at
    // the product's operator keeps it: 0 -> 3 floats, the dynamic part cheaper. Storing the
    // sum that holds the specular is refused, naming the view.
    const CliRun run = mpshade("factor examples/shaders/plastic.sl --store 10:13 --json");
    ASSERT_EQ(run.exitCode, 0) << run.output;
    const nlohmann::json doc = nlohmann::json::parse(run.output);
    EXPECT_EQ(doc["chosen_width"], 3);
    EXPECT_EQ(doc["what_if"]["without"]["chosen_width"], 0);
    EXPECT_LT(doc["cost"]["dynamic"].get<int>(),
              doc["what_if"]["without"]["dynamic_cost"].get<int>());
    const CliRun text = mpshade("factor examples/shaders/plastic.sl --store 10:13");
    EXPECT_NE(text.output.find("what-if, against the split without it:"), std::string::npos);
    const CliRun refused = mpshade("factor examples/shaders/plastic.sl --store 10:45");
    EXPECT_EQ(refused.exitCode, 2);
    EXPECT_NE(refused.output.find("plastic.sl:10:45: error: cannot store '10:45': I, the "
                                  "direction from the eye"),
              std::string::npos)
        << refused.output;
}

TEST(Cli, FactorVerifyExitsOneOverItsTolerance) {
    // The vase's splits are exact: exit 0, the verification in the JSON. The what-if of a
    // shader whose bake() freezes time, on the vase's binding, is over 1e-5: exit 1; and
    // within a tolerance above its error, 0.
    const CliRun exact = mpshade("factor --scene examples/vase/scene.json --verify --json");
    ASSERT_EQ(exact.exitCode, 0) << exact.output;
    const nlohmann::json doc = nlohmann::json::parse(exact.output);
    for (const nlohmann::json& o : doc["objects"]) {
        EXPECT_TRUE(o["verify"]["within"].get<bool>());
        EXPECT_LE(o["verify"]["max_relative"].get<double>(), 1e-5);
        EXPECT_GT(o["verify"]["points"].get<int>(), 100);
    }
    const std::string dir = tempDir("verify");
    std::filesystem::create_directories(dir);
    std::ofstream(dir + "/pulse.sl") << "surface pulse(float scale = 1) { Ci = color(bake(0.5 + "
                                        "0.5 * sin(6 * time))) * scale; }";
    const std::string what =
        "factor " + dir + "/pulse.sl --scene examples/vase/scene.json --object vase --verify";
    const CliRun over = mpshade(what);
    EXPECT_EQ(over.exitCode, 1) << over.output;
    EXPECT_NE(over.output.find("OVER --tolerance 1e-05"), std::string::npos) << over.output;
    EXPECT_EQ(mpshade(what + " --tolerance 1").exitCode, 0);
}

TEST(Cli, FactorMeasuresWhatABakeFreezesAndAWhatIfThatUndoesIt) {
    // pulse.sl bakes 0.5 + 0.5 sin(6 t): without --verify, factor says it froze frame 0
    // (t = 0, the value 0.5) and measures the stored channel's error (it holds the product
    // with the vase's scale, 2.5): at the worst frame f of the vase's 24 fps,
    // 2.5 * 0.5 |sin(6 f / 24)|, at least that of the last frame (47).
    const std::string dir = tempDir("bake-measure");
    std::filesystem::create_directories(dir);
    std::ofstream(dir + "/pulse.sl") << "surface pulse(float scale = 1) {\n"
                                        "    float p = bake(0.5 + 0.5 * sin(6 * time));\n"
                                        "    Ci = color(p) * scale;\n}\n";
    const std::string factor =
        "factor " + dir + "/pulse.sl --scene examples/vase/scene.json --object vase";
    const CliRun text = mpshade(factor);
    ASSERT_EQ(text.exitCode, 0) << text.output;
    EXPECT_NE(text.output.find("what the bakes freeze: the static run's time and view, frame 0 "
                               "(t = 0.000 s"),
              std::string::npos)
        << text.output;
    const CliRun json = mpshade(factor + " --json");
    ASSERT_EQ(json.exitCode, 0) << json.output;
    // (The note that vase uses another shader comes first, on stderr.)
    auto parsed = [](const std::string& out) {
        return nlohmann::json::parse(out.substr(std::min(out.find('{'), out.size())));
    };
    const nlohmann::json doc = parsed(json.output);
    EXPECT_EQ(doc["bake"]["frozen_at"]["frame"], 0);
    const nlohmann::json& channel = doc["bake"]["measured"]["channels"][0];
    const double worstTime = channel["worst"]["frame"].get<int>() / 24.0;
    EXPECT_NEAR(channel["max_abs"].get<double>(), 1.25 * std::abs(std::sin(6.0 * worstTime)), 1e-5);
    EXPECT_GE(channel["max_abs"].get<double>() + 1e-6, 1.25 * std::abs(std::sin(6.0 * 47 / 24.0)));
    // Repeating p on this binding undoes the bake: nothing stored, exact, and the what-if
    // measures both.
    const CliRun undone = mpshade(factor + " --repeat p --json");
    ASSERT_EQ(undone.exitCode, 0) << undone.output;
    const nlohmann::json u = parsed(undone.output);
    EXPECT_EQ(u["chosen_width"], 0);
    EXPECT_FALSE(u.contains("bake"));
    EXPECT_LE(u["what_if"]["with"]["max_relative"].get<double>(), 1e-6);
    EXPECT_NEAR(u["what_if"]["without"]["max_relative"].get<double>(),
                doc["bake"]["measured"]["max_relative"].get<double>(), 1e-9);
    EXPECT_GT(u["what_if"]["without"]["map_bytes"].get<double>(), 0.0);
}

TEST(Cli, FactorBadInput) {
    const BadRun cases[] = {
        {"factor examples/shaders/marble.sl --scene examples/vase/scene.json --object urn",
         "mpshade: --object: error: no object named 'urn' in examples/vase/scene.json (objects: "
         "vase, floor)\n"},
        {"factor examples/shaders/marble.sl --object vase",
         "mpshade: --object: error: --object needs --scene\n"},
        {"factor examples/shaders/wood.sl --scene examples/vase/scene.json --object vase",
         "mpshade: examples/shaders/wood.sl: error: object 'vase' binds parameter 'scale', which "
         "this shader does not declare\n"},
        {"factor tests/data/bad_shaders/missing_semicolon.sl",
         "mpshade: tests/data/bad_shaders/missing_semicolon.sl:3:5: error: expected ';' after the "
         "statement, found 'Ci'\n"},
        {"factor nowhere.sl", "mpshade: nowhere.sl: error: cannot open shader file\n"},
        {"factor examples/shaders",
         "mpshade: examples/shaders: error: is a folder, not a shader file\n"},
        {"factor examples/shaders/marble.sl --verify",
         "mpshade: --verify: error: --verify needs --scene (its objects' charts and frames)\n"},
        {"factor",
         "mpshade: factor: error: give a shader file, --scene SCENE (every object) or --scene "
         "SCENE --object NAME\n"},
        {"factor examples/shaders/marble.sl --scene examples/vase/scene.json",
         "mpshade: --scene: error: --scene with a shader file needs --object NAME (without a "
         "shader file: every object, each with its own shader)\n"},
    };
    for (const BadRun& c : cases) {
        const CliRun run = mpshade(c.args);
        EXPECT_EQ(run.exitCode, 2) << c.args << "\n" << run.output;
        EXPECT_EQ(run.output, c.expected) << c.args;
    }
}

TEST(Cli, CostImagesShowWhereAFramesDynamicShadingGoes) {
    // The teapot at per-pixel shading: each pixel one surface covers whole has one point,
    // costing that object's dynamic part as factor reports it (the teapot's plastic and the
    // table's brick differ); the background none. The points add up to those the frame
    // shaded, and each object's cost to its points times its cost.
    const std::string out = tempDir("cost-images");
    const CliRun run = mpshade(
        "render examples/teapot/scene.json --frames 0:1 --shading-rate pixel "
        "--no-single-phase --cost-images --quiet --out " +
        out);
    ASSERT_EQ(run.exitCode, 0) << run.output;
    const CliRun factor = mpshade("factor --scene examples/teapot/scene.json --json");
    ASSERT_EQ(factor.exitCode, 0) << factor.output;
    std::map<std::string, double> costOf;
    const nlohmann::json factored = nlohmann::json::parse(factor.output);
    for (const nlohmann::json& o : factored["objects"])
        costOf[o["object"].get<std::string>()] = o["cost"]["dynamic"].get<double>();
    ASSERT_EQ(costOf.size(), 2u);
    ASSERT_NE(costOf["teapot"], costOf["table"]);

    std::ifstream statsFile(out + "/stats.json");
    const nlohmann::json frame = nlohmann::json::parse(statsFile)["frames"][0];
    const nlohmann::json& image = frame["cost_image"];
    EXPECT_NEAR(image["points"].get<double>(), frame["shaded_points"].get<double>(), 0.01);
    for (const auto& [name, o] : image["objects"].items())
        EXPECT_NEAR(o["cost"].get<double>(), o["points"].get<double>() * costOf[name], 1.0) << name;
    EXPECT_EQ(image["objects"].size(), 2u);

    OIIO::ImageBuf exr(out + "/cost_0000.exr");
    ASSERT_TRUE(exr.read()) << exr.geterror();
    const int points = exr.spec().channelindex("points"), cost = exr.spec().channelindex("cost");
    ASSERT_GE(points, 0);
    ASSERT_GE(cost, 0);
    auto at = [&](int x, int y, int channel) { return exr.getchannel(x, y, 0, channel); };
    EXPECT_EQ(at(0, 0, points), 0.0f);  // the background
    EXPECT_EQ(at(0, 0, cost), 0.0f);
    EXPECT_EQ(at(240, 135, points), 1.0f);  // the teapot's body
    EXPECT_EQ(at(240, 135, cost), static_cast<float>(costOf["teapot"]));
    EXPECT_EQ(at(240, 300, points), 1.0f);  // the table in front
    EXPECT_EQ(at(240, 300, cost), static_cast<float>(costOf["table"]));
    double sum = 0.0;
    for (int y = 0; y < exr.spec().height; ++y)
        for (int x = 0; x < exr.spec().width; ++x) sum += at(x, y, points);
    EXPECT_NEAR(sum, frame["shaded_points"].get<double>(), 0.05);
    EXPECT_TRUE(std::filesystem::exists(out + "/cost_0000.png"));

    // Only the multi-phase renderer has a dynamic phase to show.
    const CliRun reference =
        mpshade("render examples/teapot/scene.json --mode reference --cost-images --out " + out);
    EXPECT_EQ(reference.exitCode, 2);
    EXPECT_NE(reference.output.find("--cost-images"), std::string::npos) << reference.output;
}

}  // namespace
