// scene_fixtures.h -- cameras, view directions and a generated scene shared by the tests of
// the warp, the rasterizer and the multi-phase renderer.
#pragma once

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "geometry/point_cloud.h"
#include "phases/scene_resources.h"
#include "test_support.h"

namespace mpshade::test {

inline CameraState lookAt(const glm::vec3& eye, const glm::vec3& target, int w, int h,
                          float fovY = 40.0f, float zNear = 0.05f) {
    CameraState c;
    c.eye = eye;
    c.forward = glm::normalize(target - eye);
    glm::vec3 up(0, 1, 0);
    if (std::fabs(glm::dot(up, c.forward)) > 0.99f) up = glm::vec3(1, 0, 0);
    c.right = glm::normalize(glm::cross(c.forward, up));
    c.up = glm::cross(c.right, c.forward);
    c.tanHalfFovY = std::tan(glm::radians(fovY) * 0.5f);
    c.aspect = float(w) / float(h);
    c.zNear = zNear;
    c.zFar = 1e6f;
    c.width = w;
    c.height = h;
    return c;
}

// A random point on the sphere of directions within `angle` degrees of `axis`.
inline glm::vec3 directionNear(const glm::vec3& axis, float angle, std::mt19937& rng) {
    std::uniform_real_distribution<float> uni(0.0f, 1.0f);
    const float cosMax = std::cos(glm::radians(angle));
    const float z = 1.0f - uni(rng) * (1.0f - cosMax), phi = 6.2831853f * uni(rng);
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    glm::vec3 T, B;
    orthonormalBasis(axis, T, B);
    return glm::normalize(r * std::cos(phi) * T + r * std::sin(phi) * B + z * axis);
}

inline std::string writeBlobScene(const std::string& name, int frames, std::mt19937& rng) {
    // A closed Loop-subdivision blob in white on black, the camera jumping between random
    // views inside the range of the first.
    const std::string dir = ::testing::TempDir() + "mpshade_multiphase_" + name + "/";
    std::filesystem::create_directories(dir);
    std::ofstream(dir + "white.sl") << "surface white() { Ci = color(1); }";
    std::ofstream json(dir + "scene.json");
    json
        << R"({ "settings": { "width": 48, "height": 48, "samples_per_pixel": 2, "fps": 1, "duration": )"
        << frames
        << R"(, "background": [0, 0, 0] }, "camera": { "fov_y": 30, "near": 0.05, "far": 100, "keys": [)";
    const glm::vec3 axis = glm::normalize(glm::vec3(0.4f, 0.5f, 1.0f));
    for (int f = 0; f < frames; ++f) {
        const float factor =
            f == 0 ? 1.0f : std::exp2(std::uniform_real_distribution<float>(-0.28f, 0.28f)(rng));
        const glm::vec3 eye = 4.0f * factor * (f == 0 ? axis : directionNear(axis, 17.0f, rng));
        json << (f ? "," : "") << "{ \"t\": " << f << ", \"eye\": [" << eye.x << "," << eye.y << ","
             << eye.z << "], \"target\": [0, 0, 0] }";
    }
    json
        << R"(] }, "shaders": { "white": "white.sl" }, "objects": [ { "name": "blob",
          "geometry": { "type": "subdiv", "file": ")"
        << test::sourcePath("tests/data/meshes/octahedron.obj")
        << R"(", "scheme": "loop" }, "shader": "white", "range": { "distance_factor": 1.25, "angle": 20 } } ] })";
    return dir + "scene.json";
}

}  // namespace mpshade::test
