// The static phase's dicing of an object's separate or direct facets (static_phase.h):
// chart coordinates are kept exact where a shader map is probed at them or the shader
// reads them, and only the surface counts where nothing does.
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "phases/static_phase.h"
#include "scene/scene.h"

namespace mpshade {
namespace {

// Three discs of radius 1 seen from 4 units above, shaded by `source`.
std::string writeDiscScene(const std::string& name, const std::string& source) {
    const std::string dir = ::testing::TempDir() + "mpshade_static_" + name + "/";
    std::filesystem::create_directories(dir);
    std::ofstream(dir + "s.sl") << source;
    std::ofstream(dir + "discs.pts") << "0 0 0 0 1 0 1\n2.5 0 0 0 1 0 1\n-2.5 0 0 0 1 0.2 1\n";
    std::ofstream(dir + "scene.json") << R"({ "settings": { "width": 320, "height": 180,
      "samples_per_pixel": 4, "fps": 1, "duration": 1, "background": [0, 0, 0] },
      "camera": { "fov_y": 40, "near": 0.05, "far": 100,
                  "keys": [ { "t": 0, "eye": [0.3, 4, 1.5], "target": [0, 0, 0] } ] },
      "lights": [ { "type": "distant", "direction": [-1, -2, -1], "color": [1, 1, 1] } ],
      "shaders": { "s": "s.sl" },
      "objects": [ { "name": "discs", "geometry": { "type": "points", "file": "discs.pts" },
                     "shader": "s", "representation": "shadermap" } ] })";
    return dir + "scene.json";
}

// The facets of the discs' separate representation at frame 0, and whether it has a map.
size_t separateFacets(const std::string& name, const std::string& source, bool& mapped) {
    const Scene scene = loadScene(writeDiscScene(name, source));
    const SceneResources resources(scene, SceneResources::RayScenes::ForOcclusion);
    const StaticPhase statics(scene, resources);
    const FrameState state = frameStateAt(resources, 0, 320, 180, 4);
    StaticCosts costs;
    const std::unique_ptr<ObjectRepresentation> rep =
        statics.build(0, Representation::ShaderMap, state.objects[0], state.camera,
                      state.uniforms[0], nullptr, costs);
    mapped = rep->map != nullptr;
    return rep->mesh.facetCount();
}

TEST(StaticPhase, ChartCoordinatesAreDicedExactlyOnlyWhereSomethingReadsThem) {
    // Stored noise (a map probed at the facets' chart coordinates), a shader of the normal
    // alone (nothing stored, nothing read in chart coordinates) and one of (u, v) (nothing
    // stored, but the dynamic part interpolates u and v per vertex). A disc's polar chart
    // has diagonals that stray far from its own points: kept exact, they take many times
    // the facets its flat surface needs.
    bool mapped = false, plainMapped = true, chartMapped = true;
    const size_t withMap = separateFacets(
        "mapped", "surface s() { Ci = color(bake(fbm(P * 8.0, 6)), 0.2, 0.1) * (1 + time); }",
        mapped);
    const size_t plain = separateFacets(
        "plain", "surface s() { Ci = color(0.5 + 0.5 * N[1], 0.2, 0.1); }", plainMapped);
    const size_t chart =
        separateFacets("chart", "surface s() { Ci = color(u, v, 0.1); }", chartMapped);
    EXPECT_TRUE(mapped);
    EXPECT_FALSE(plainMapped);
    EXPECT_FALSE(chartMapped);
    EXPECT_LT(4 * plain, withMap);
    EXPECT_EQ(chart, withMap);
}

}  // namespace
}  // namespace mpshade
