// The scene file: golden errors for a corpus of bad scenes, keys, the evolving scene at
// time t, and which inputs of each object vary.
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "geometry/error.h"
#include "scene/json_reader.h"
#include "scene/scene.h"
#include "scene/scene_state.h"
#include "scene/variability.h"
#include "test_support.h"

namespace mpshade {
namespace {

using test::sourcePath;

struct BadScene {
    const char* name;
    const char* file;      // the file the error must name: "" = the scene itself
    const char* jsonPath;  // "" when the error is not in JSON
    int line, column;
    const char* message;
};

const BadScene kBadScenes[] = {
    {"missing_camera", "", "(top level)", 0, 0, "missing required key 'camera'"},
    {"extra_key", "", "objects[0].colour", 0, 0,
     "unknown key 'colour' (expected one of: name, geometry, shader, params, transform, keys, "
     "representation, shadermap_resolution, shadermap_precision, factoring, range)"},
    {"wrong_type", "", "objects[0].geometry.radius", 0, 0, "expected a number, found a string"},
    {"negative_radius", "", "objects[0].geometry.radius", 0, 0,
     "expected a positive number, found -1"},
    {"missing_obj", "", "objects[0].geometry.file", 0, 0,
     "file '../meshes/nope.obj' not found (looked for "},
    {"folder_obj", "", "objects[0].geometry.file", 0, 0, "'../meshes' is a folder, not a file ("},
    {"malformed_obj", "tests/data/meshes/bad_number.obj", "", 2, 7,
     "expected a number, found 'zero' (loading objects[0].geometry of "},
    {"bad_obj_index", "tests/data/meshes/bad_index.obj", "", 4, 7,
     "vertex index 4 is out of range (3 defined so far) (loading objects[0].geometry of "},
    {"unsorted_keys", "", "camera.keys[1].t", 0, 0,
     "keys must be sorted by strictly increasing t (previous key has t = 1)"},
    {"empty_scene", "", "objects", 0, 0, "the scene has no objects"},
    {"zero_size", "", "settings.width", 0, 0, "expected a whole number in [1, 16384], found 0"},
    {"zero_plane", "", "objects[0].geometry.size[0]", 0, 0, "expected a positive number, found 0"},
    {"unknown_shader", "", "objects[0].shader", 0, 0, "no shader named 'marble' in 'shaders'"},
    {"unknown_param", "", "objects[0].params.Kss", 0, 0,
     "shader 'plastic' has no parameter 'Kss' (it has: Cs, Kd, Ks, roughness)"},
    {"param_type", "", "objects[0].params.Cs", 0, 0,
     "expected an array of 3 numbers, found a string"},
    {"unknown_geometry", "", "objects[0].geometry.type", 0, 0,
     "unknown geometry type 'cone' (expected sphere, torus, plane, bezier, subdiv, mesh or "
     "points)"},
    {"eye_is_target", "", "camera", 0, 0, "eye and target coincide at t = 0"},
    {"bad_light", "", "lights[2].type", 0, 0,
     "unknown light type 'spot' (expected ambient, distant or point)"},
    {"negative_color", "", "lights[0].color", 0, 0, "color components must be non-negative"},
    {"bad_shader", "tests/data/bad_shaders/missing_semicolon.sl", "", 3, 5,
     "expected ';' after the statement, found 'Ci' (loading shaders.plastic of "},
    {"bad_points", "tests/data/meshes/bad_points.txt", "", 2, 0,
     "the normal is zero (loading objects[0].geometry of "},
    {"loop_quads", "tests/data/meshes/cube.obj", "", 0, 0,
     "face 0 has 4 sides; the loop scheme takes triangles only (loading objects[0].geometry of "},
    {"empty_keys", "", "objects[0].keys", 0, 0, "expected at least one key"},
    {"nonuniform_scale", "", "objects[0].transform.scale", 0, 0,
     "scale must be one positive number (mpshade supports uniform scale only)"},
    {"duplicate_name", "", "objects[1].name", 0, 0, "another object is already named 'ball'"},
    {"far_before_near", "", "camera", 0, 0, "far (0.01) must exceed near (0.1)"},
    {"syntax_error", "", "", 2, 30,
     "invalid JSON: syntax error while parsing object key - unexpected '}'; expected string "
     "literal"},
    {"nan_value", "", "", 79, 19,
     "invalid JSON: syntax error while parsing value - invalid literal; last read: '\"radius\": "
     "N'"},
    {"inf_value", "", "", 79, 19,
     "invalid JSON: number overflow parsing '1e999' (numbers must be finite floats)"},
    {"empty_file", "", "", 1, 1,
     "invalid JSON: syntax error while parsing value - unexpected end of input; expected '[', '{', "
     "or a literal"},
    {"not_an_object", "", "(top level)", 0, 0, "a scene must be a JSON object"},
    {"deep_nesting", "", "", 1, 77, "invalid JSON: nested more than 64 levels deep"},
    {"camera_at_1e38", "", "camera.eye", 0, 0,
     "coordinates must be within 1e8 of the origin (found 1e38)"},
    {"scale_1e-30", "", "objects[0].transform.scale", 0, 0,
     "expected a length in [1e-8, 1e8], found 1e-30"},
    {"unknown_representation", "", "objects[0].representation", 0, 0,
     "unknown representation 'directly' (expected auto, facets, shadermap or direct)"},
    {"bad_shading_rate", "", "settings.shading_rate", 0, 0,
     "unknown shading_rate 'octant' (expected sample, pixel or quad)"},
    {"plane_1e30", "", "objects[0].geometry.size[0]", 0, 0,
     "expected a length in [1e-8, 1e8], found 1e30"},
    {"deep_shader", "tests/data/bad_shaders/deep_parens.sl", "", 3, 526,
     "the shader nests more than 512 levels deep here (blocks, parentheses and operators each "
     "count one; a chain like a + b + c one per operator): split it with variables (loading "
     "shaders.deep of "},
    {"animated_count", "tests/data/shaders/counted.sl", "", 3, 32,
     "the occlusion ray count must be a constant (binding objects[0] 'ball' of "},
};

TEST(BadScenes, GoldenErrors) {
    size_t checked = 0;
    for (const BadScene& bad : kBadScenes) {
        const std::string path =
            sourcePath(std::string("tests/data/bad_scenes/") + bad.name + ".json");
        try {
            loadScene(path);
            ADD_FAILURE() << bad.name << " was accepted";
        } catch (const InputError& e) {
            const std::string expectedFile =
                *bad.file ? std::filesystem::path(sourcePath(bad.file)).lexically_normal().string()
                          : path;
            EXPECT_EQ(e.where().file, expectedFile) << bad.name;
            EXPECT_EQ(e.where().jsonPath, bad.jsonPath) << bad.name;
            EXPECT_EQ(e.where().line, bad.line) << bad.name;
            EXPECT_EQ(e.where().column, bad.column) << bad.name;
            EXPECT_EQ(e.message().rfind(bad.message, 0), 0u) << bad.name << ": " << e.message();
        }
        ++checked;
    }
    // Every file of the corpus is in the table.
    size_t files = 0;
    for (const auto& entry :
         std::filesystem::directory_iterator(sourcePath("tests/data/bad_scenes")))
        files += entry.path().extension() == ".json";
    EXPECT_EQ(files, checked);
}

TEST(BadScenes, AFolderOrAMissingFileIsNamedAsSuch) {
    const std::filesystem::path folder =
        std::filesystem::path(::testing::TempDir()) / "mpshade_scene_folder.json";
    std::filesystem::create_directories(folder);
    const std::pair<std::string, std::string> cases[] = {
        {folder.string(), "is a folder, not a scene file"},
        {(folder / "absent.json").string(), "cannot open scene file"}};
    for (const auto& [path, message] : cases) {
        try {
            loadScene(path);
            ADD_FAILURE() << path << " was accepted";
        } catch (const InputError& e) {
            EXPECT_EQ(e.where().file, path);
            EXPECT_EQ(e.message(), message);
        }
    }
}

TEST(BadScenes, JsonNestingStopsJustPastItsLimit) {
    // 64 levels (the object and 63 arrays, brackets inside a string not counted) are read
    // and judged as a scene; one more is the nesting error at that bracket.
    const std::string dir = testing::TempDir();
    const auto write = [&](int arrays) {
        const std::string path = dir + "/nest" + std::to_string(arrays) + ".json";
        std::ofstream(path) << "{\"settings\": " << std::string(static_cast<size_t>(arrays), '[')
                            << "\"[[[[\"" << std::string(static_cast<size_t>(arrays), ']') << "}";
        return path;
    };
    try {
        loadScene(write(kMaxJsonNesting - 1));
        ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
        EXPECT_EQ(e.where().jsonPath, "settings") << e.what();
    }
    try {
        loadScene(write(kMaxJsonNesting));
        ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
        EXPECT_EQ(e.message(), "invalid JSON: nested more than 64 levels deep");
        EXPECT_EQ(e.where().column, 13 + kMaxJsonNesting);
    }
}

TEST(BadScenes, CoordinateAndLengthLimitsHoldOnTheBoundary) {
    // The limits themselves load; just past them is the error.
    const std::string dir = testing::TempDir();
    const auto scene = [&](const std::string& eye, const std::string& scale,
                           const std::string& radius) {
        const std::string path = dir + "/limits.json";
        std::ofstream(path) << R"({"camera": {"eye": )" << eye
                            << R"(, "target": [0, 0, 0]}, "shaders": {"p": ")"
                            << sourcePath("examples/shaders/plastic.sl")
                            << R"("}, "objects": [{"name": "b", "shader": "p", "geometry": )"
                            << R"({"type": "sphere", "radius": )" << radius
                            << R"(}, "transform": {"scale": )" << scale << "}}]}";
        return path;
    };
    EXPECT_NO_THROW(loadScene(scene("[1e8, -1e8, 0]", "1e-8", "1e8")));
    EXPECT_NO_THROW(loadScene(scene("[0, 0, 5]", "1e8", "1e-8")));
    EXPECT_THROW(loadScene(scene("[1.0001e8, 0, 0]", "1", "1")), InputError);
    EXPECT_THROW(loadScene(scene("[0, 0, 5]", "0.9999e-8", "1")), InputError);
    EXPECT_THROW(loadScene(scene("[0, 0, 5]", "1", "1.0001e8")), InputError);
}

TEST(SceneLoader, EqualShapesShareOneSurface) {
    // 20,000 equal spheres once took a tessellation and a ray scene each (40 GB); equal
    // shapes now share one, and shapes differing in the last bit do not.
    const std::string path = testing::TempDir() + "/shared.json";
    std::ofstream(path) << R"({"camera": {"eye": [0, 0, 5], "target": [0, 0, 0]},
      "shaders": {"p": ")"
                        << sourcePath("examples/shaders/plastic.sl") << R"("},
      "objects": [
        {"name": "a", "shader": "p", "geometry": {"type": "sphere", "radius": 0.5}},
        {"name": "b", "shader": "p", "geometry": {"type": "sphere", "radius": 0.5}},
        {"name": "c", "shader": "p", "geometry": {"type": "sphere", "radius": 0.50000006}},
        {"name": "d", "shader": "p", "geometry": {"type": "torus", "major": 1, "minor": 0.25}},
        {"name": "e", "shader": "p", "geometry": {"type": "torus", "major": 1, "minor": 0.25}},
        {"name": "f", "shader": "p", "geometry": {"type": "plane", "size": [2, 3]}},
        {"name": "g", "shader": "p", "geometry": {"type": "plane", "size": [3, 2]}}]})";
    const Scene scene = loadScene(path);
    EXPECT_EQ(scene.objects[0].surface, scene.objects[1].surface);
    EXPECT_NE(scene.objects[0].surface, scene.objects[2].surface);
    EXPECT_EQ(scene.objects[3].surface, scene.objects[4].surface);
    EXPECT_NE(scene.objects[5].surface, scene.objects[6].surface);
}

TEST(BadScenes, EveryDocumentedRangeOnBothSidesOfItsBound) {
    // Each range docs/scene-format.md documents: a value just inside loads, one just
    // outside is an error naming that value's JSON path.
    struct Edge {
        const char* settings;  // JSON members of "settings"
        const char* camera;    // extra members of "camera"
        const char* object;    // extra members of the object
        const char* geometry;  // the object's geometry
        const char* badPath;   // "" if the scene must load
    };
    const char* sphere = R"({"type": "sphere", "radius": 1})";
    const Edge kEdges[] = {
        {R"("width": 16384, "height": 1)", "", "", sphere, ""},
        {R"("width": 16385)", "", "", sphere, "settings.width"},
        {R"("height": 0)", "", "", sphere, "settings.height"},
        {R"("samples_per_pixel": 1024)", "", "", sphere, ""},
        {R"("samples_per_pixel": 1025)", "", "", sphere, "settings.samples_per_pixel"},
        {R"("samples_per_pixel": 0)", "", "", sphere, "settings.samples_per_pixel"},
        {R"("fps": 1000, "duration": 1000)", "", "", sphere, ""},  // a million frames
        {R"("fps": 1000.001)", "", "", sphere, "settings.fps"},
        {R"("fps": 1000, "duration": 1000.01)", "", "", sphere, "settings.duration"},
        {R"("fps": 0)", "", "", sphere, "settings.fps"},
        {R"("duration": 0)", "", "", sphere, "settings.duration"},
        {"", R"(, "fov_y": 179.9)", "", sphere, ""},
        {"", R"(, "fov_y": 180)", "", sphere, "camera.fov_y"},
        {"", R"(, "fov_y": 0)", "", sphere, "camera.fov_y"},
        {"", R"(, "near": 0.5, "far": 0.50001)", "", sphere, ""},
        {"", R"(, "near": 0.5, "far": 0.5)", "", sphere, "camera"},
        {"", R"(, "near": 0)", "", sphere, "camera.near"},
        {"", "", R"(, "range": {"distance_factor": 1.0001, "angle": 180})", sphere, ""},
        {"", "", R"(, "range": {"distance_factor": 1})", sphere,
         "objects[0].range.distance_factor"},
        {"", "", R"(, "range": {"angle": 180.001})", sphere, "objects[0].range.angle"},
        {"", "", R"(, "range": {"angle": 0})", sphere, "objects[0].range.angle"},
        {"", "", R"(, "shadermap_resolution": 1048576)", sphere, ""},
        {"", "", R"(, "shadermap_resolution": 1048577)", sphere, "objects[0].shadermap_resolution"},
        {"", "", R"(, "shadermap_resolution": 0)", sphere, "objects[0].shadermap_resolution"},
        {"", "", R"(, "shadermap_precision": "half")", sphere, ""},
        {"", "", R"(, "shadermap_precision": "float")", sphere, ""},
        {"", "", R"(, "shadermap_precision": "auto")", sphere, ""},
        {"", "", R"(, "shadermap_precision": "double")", sphere, "objects[0].shadermap_precision"},
        {"", "", R"(, "shadermap_precision": 16)", sphere, "objects[0].shadermap_precision"},
        {"", "", R"(, "factoring": {"store": ["10:13"], "repeat": []})", sphere, ""},
        {"", "", R"(, "factoring": {"store": ["1:x"]})", sphere, "objects[0].factoring.store[0]"},
        {"", "", R"(, "factoring": {"repeat": ["a b"]})", sphere, "objects[0].factoring.repeat[0]"},
        {"", "", R"(, "factoring": {"keep": []})", sphere, "objects[0].factoring.keep"},
        {"", "", "", R"({"type": "torus", "major": 1, "minor": 0.999})", ""},
        {"", "", "", R"({"type": "torus", "major": 1, "minor": 1})", "objects[0].geometry.minor"},
        {"", "", "", R"({"type": "plane", "size": [1e-8, 1e8]})", ""},
        {"", "", "", R"({"type": "plane", "size": [1, 0]})", "objects[0].geometry.size[1]"},
    };
    const std::string path = testing::TempDir() + "/edge.json";
    for (const Edge& e : kEdges) {
        std::ofstream(path) << R"({"settings": {)" << e.settings
                            << R"(}, "camera": {"eye": [0, 0, 5], "target": [0, 0, 0])" << e.camera
                            << R"(}, "shaders": {"p": ")"
                            << sourcePath("examples/shaders/plastic.sl")
                            << R"("}, "objects": [{"name": "o", "shader": "p", "geometry": )"
                            << e.geometry << e.object << "}]}";
        const std::string what = std::string(e.settings) + e.camera + e.object + e.geometry;
        if (!*e.badPath) {
            EXPECT_NO_THROW(loadScene(path)) << what;
            continue;
        }
        try {
            loadScene(path);
            ADD_FAILURE() << "accepted: " << what;
        } catch (const InputError& err) {
            EXPECT_EQ(err.where().jsonPath, e.badPath) << what << ": " << err.what();
        }
    }
}

TEST(Keyframes, InterpolateLinearlyAndHoldOutside) {
    Keyframes<float> k;
    k.times = {1.0f, 3.0f};
    k.values = {10.0f, 30.0f};
    EXPECT_EQ(k.at(0.0f), 10.0f);
    EXPECT_EQ(k.at(1.0f), 10.0f);
    EXPECT_EQ(k.at(2.0f), 20.0f);
    EXPECT_EQ(k.at(2.5f), 25.0f);
    EXPECT_EQ(k.at(9.0f), 30.0f);
    EXPECT_TRUE(k.varies());
    k.values = {5.0f, 5.0f};
    EXPECT_FALSE(k.varies());
    // Three keys, unevenly spaced: each span interpolates over its own length.
    k.times = {0.0f, 1.0f, 5.0f};
    k.values = {0.0f, 10.0f, 50.0f};
    EXPECT_EQ(k.at(0.5f), 5.0f);
    EXPECT_EQ(k.at(3.0f), 30.0f);
    EXPECT_EQ(k.at(4.0f), 40.0f);
}

class ExampleScenes : public ::testing::TestWithParam<const char*> {};

TEST_P(ExampleScenes, LoadAndBind) {
    const Scene scene = loadScene(sourcePath(GetParam()));
    EXPECT_GT(scene.objects.size(), 0u);
    EXPECT_GT(scene.frameCount(), 1);
    for (const SceneObject& obj : scene.objects) {
        const ObjectVariability v = variabilityOf(scene, obj);
        EXPECT_EQ(v.lightMovesRelative.size(), scene.lights.size());
        const ShaderBinding b = bindingOf(scene, obj);
        EXPECT_EQ(b.lights.size(), scene.lights.size());
    }
}

INSTANTIATE_TEST_SUITE_P(All, ExampleScenes,
                         ::testing::Values("examples/vase/scene.json", "examples/teapot/scene.json",
                                           "examples/courtyard/scene.json",
                                           "examples/vase/lamplight.json"));

std::string writeScene(const std::string& name, const std::string& json) {
    // A folder of the test's own: ctest runs this file's tests in parallel processes, each
    // rewriting s.sl.
    const std::string dir = ::testing::TempDir() + "mpshade_scene_test_" +
                            ::testing::UnitTest::GetInstance()->current_test_info()->name() + "/";
    std::filesystem::create_directories(dir);
    std::ofstream(dir + "s.sl")
        << "surface s(float k = 1, color c = 0) { Ci = c * k + diffuse(N) + color(time); }";
    std::ofstream(dir + name) << json;
    return dir + name;
}

TEST(SceneLoader, MapPrecisionIsAutoUnlessTheObjectSaysFloatOrHalf) {
    const std::string path = writeScene("precision.json", R"({
      "camera": { "eye": [0, 0, 5], "target": [0, 0, 0] }, "shaders": { "s": "s.sl" },
      "objects": [ { "name": "a", "geometry": { "type": "sphere", "radius": 1 }, "shader": "s" },
                   { "name": "f", "geometry": { "type": "sphere", "radius": 1 }, "shader": "s",
                     "shadermap_precision": "float" },
                   { "name": "h", "geometry": { "type": "sphere", "radius": 1 }, "shader": "s",
                     "shadermap_precision": "half" },
                   { "name": "x", "geometry": { "type": "sphere", "radius": 1 }, "shader": "s",
                     "shadermap_precision": "auto" } ] })");
    const Scene scene = loadScene(path);
    ASSERT_EQ(scene.objects.size(), 4u);
    EXPECT_EQ(scene.objects[0].shadermapPrecision, MapPrecision::Auto);
    EXPECT_EQ(scene.objects[1].shadermapPrecision, MapPrecision::Float);
    EXPECT_EQ(scene.objects[2].shadermapPrecision, MapPrecision::Half);
    EXPECT_EQ(scene.objects[3].shadermapPrecision, MapPrecision::Auto);
}

TEST(Variability, FollowsWhatTheSceneAnimates) {
    const std::string path = writeScene("var.json", R"({
      "camera": { "eye": [0, 0, 5], "target": [0, 0, 0] },
      "lights": [ { "type": "ambient", "color": [0.1, 0.1, 0.1] },
                  { "type": "distant", "direction": [0, -1, 0] },
                  { "type": "point", "position": [0, 3, 0],
                    "keys": [ { "t": 0, "position": [0, 3, 0] }, { "t": 1, "position": [1, 3, 0] } ] } ],
      "shaders": { "s": "s.sl" },
      "objects": [
        { "name": "still", "geometry": { "type": "sphere", "radius": 1 }, "shader": "s",
          "params": { "k": 2, "c": { "keys": [ { "t": 0, "value": [1, 0, 0] }, { "t": 1, "value": [0, 1, 0] } ] } } },
        { "name": "moving", "geometry": { "type": "sphere", "radius": 1 }, "shader": "s",
          "params": { "c": { "keys": [ { "t": 0, "value": 1 }, { "t": 1, "value": 1 } ] } },
          "keys": [ { "t": 0, "translate": [0, 0, 0] }, { "t": 1, "translate": [1, 0, 0] } ] },
        { "name": "spinning", "geometry": { "type": "sphere", "radius": 1 }, "shader": "s",
          "keys": [ { "t": 0, "rotate": [0, 1, 0, 0] }, { "t": 1, "rotate": [0, 1, 0, 30] } ] },
        { "name": "growing", "geometry": { "type": "sphere", "radius": 1 }, "shader": "s",
          "keys": [ { "t": 0, "scale": 1 }, { "t": 1, "scale": 2 } ] } ]
    })");
    const Scene scene = loadScene(path);
    const ObjectVariability still = variabilityOf(scene, scene.objects[0]);
    EXPECT_FALSE(still.cameraMoves);
    EXPECT_FALSE(still.transformAnimated);
    EXPECT_EQ(still.lightMovesRelative, (std::vector<bool>{false, false, true}));
    EXPECT_EQ(still.animatedParams, std::vector<std::string>{"c"});
    const ObjectVariability moving = variabilityOf(scene, scene.objects[1]);
    EXPECT_TRUE(moving.transformAnimated);
    // Translation moves the point light relative to the object, not the distant light's
    // direction; an ambient light has no position.
    EXPECT_EQ(moving.lightMovesRelative, (std::vector<bool>{false, false, true}));
    // Rotation turns the distant light's direction in object space.
    const ObjectVariability spinning = variabilityOf(scene, scene.objects[2]);
    EXPECT_TRUE(spinning.transformAnimated);
    EXPECT_EQ(spinning.lightMovesRelative, (std::vector<bool>{false, true, true}));
    // A uniform scale keeps directions; the point light's object-space position scales.
    const ObjectVariability growing = variabilityOf(scene, scene.objects[3]);
    EXPECT_EQ(growing.lightMovesRelative, (std::vector<bool>{false, false, true}));
    // Keys with equal values do not animate.
    EXPECT_TRUE(moving.animatedParams.empty());
    const ShaderBinding b = bindingOf(scene, scene.objects[0]);
    EXPECT_EQ(b.params.at("k").kind, ParamBinding::Kind::Constant);
    EXPECT_EQ(b.params.at("k").value[0], 2.0f);
    EXPECT_EQ(b.params.at("c").kind, ParamBinding::Kind::Animated);
}

TEST(SceneState, CameraRaysAndProjectionAgree) {
    const Scene scene = loadScene(sourcePath("examples/vase/scene.json"));
    const CameraState cam = cameraAt(scene, 0.5f, 320, 200);
    for (float x : {0.5f, 100.0f, 319.5f}) {
        for (float y : {0.5f, 77.0f, 199.5f}) {
            float px, py;
            ASSERT_TRUE(cam.project(cam.eye + 3.0f * cam.direction(x, y), px, py));
            EXPECT_NEAR(px, x, 1e-3f);
            EXPECT_NEAR(py, y, 1e-3f);
        }
    }
    // The image centre looks at the target.
    const glm::vec3 toTarget = glm::normalize(scene.camera.target.at(0.5f) - cam.eye);
    EXPECT_NEAR(glm::dot(cam.direction(160, 100), toTarget), 1.0f, 1e-5f);
}

TEST(SceneState, LightsInObjectSpaceKeepWorldFalloff) {
    const std::string path = writeScene("lights.json", R"({
      "camera": { "eye": [0, 0, 5], "target": [0, 0, 0] },
      "lights": [ { "type": "point", "position": [0, 4, 0], "intensity": 16 },
                  { "type": "distant", "direction": [0, -1, 0] } ],
      "shaders": { "s": "s.sl" },
      "objects": [ { "name": "o", "geometry": { "type": "sphere", "radius": 1 }, "shader": "s",
                     "transform": { "translate": [0, 2, 0], "rotate": [0, 0, 1, 90], "scale": 2 } } ]
    })");
    const Scene scene = loadScene(path);
    const CameraState cam = cameraAt(scene, 0, 64, 64);
    const ObjectState st = objectAt(scene.objects[0], 0, cam);
    std::vector<LightSample> lights;
    lightsAt(scene, st, 0, lights);
    // World: light 2 above the object's origin. Object space: 1 unit away, along -x
    // (the object is rotated 90 degrees about z), with the world's 1/d^2 kept.
    EXPECT_NEAR(glm::length(lights[0].position - glm::vec3(1, 0, 0)), 0.0f, 1e-5f);
    const float worldIrradiance = 16.0f / (2.0f * 2.0f);
    EXPECT_NEAR(lights[0].color.x / glm::dot(lights[0].position, lights[0].position),
                worldIrradiance, 1e-4f);
    EXPECT_NEAR(glm::length(lights[1].toLight - glm::vec3(1, 0, 0)), 0.0f, 1e-5f);
}

TEST(SceneLoader, NegativeZeroColoursLoadAsPositiveZero) {
    // The shaders' light sums start from their first light (shading/lower.cpp), exact only
    // while no light's term is -0: a colour of -0 loads as +0, and -0.0001 is still an error.
    const auto scene = [](const std::string& color) {
        return writeScene("zero_color.json", R"({
      "camera": { "eye": [0, 0, 5], "target": [0, 0, 0] },
      "lights": [ { "type": "distant", "direction": [0, -1, 0], "color": )" +
                                                 color + R"( } ],
      "shaders": { "s": "s.sl" },
      "objects": [ { "name": "o", "geometry": { "type": "sphere", "radius": 1 }, "shader": "s" } ]
    })");
    };
    const Scene s = loadScene(scene("[-0.0, 1, -0]"));
    const CameraState cam = cameraAt(s, 0, 64, 64);
    std::vector<LightSample> lights;
    lightsAt(s, objectAt(s.objects[0], 0, cam), 0, lights);
    ASSERT_EQ(lights.size(), 1u);
    EXPECT_FALSE(std::signbit(lights[0].color.x));
    EXPECT_FALSE(std::signbit(lights[0].color.z));
    EXPECT_EQ(lights[0].color.y, 1.0f);
    EXPECT_THROW(loadScene(scene("[-0.0001, 1, 0]")), InputError);
}

}  // namespace
}  // namespace mpshade
