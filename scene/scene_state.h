// scene_state.h -- the evolving scene at one time t: the camera, and for each object its
// transform and everything its shader reads (animated parameters, lights in the object's
// own coordinates, the eye in object coordinates).
#pragma once

#include <vector>

#include <glm/mat4x4.hpp>

#include "scene/scene.h"
#include "shading/interpreter.h"
#include "shading/ir.h"

namespace mpshade {

// A pinhole camera at time t. World space; the image plane spans pixels [0, width) x
// [0, height), y down.
struct CameraState {
    glm::vec3 eye, forward, right, up;  // orthonormal frame; right x up = -forward
    float tanHalfFovY = 0.0f;
    float aspect = 1.0f;  // width / height
    float zNear = 0.0f, zFar = 0.0f;
    int width = 0, height = 0;

    // Unit direction through image position (x, y) in pixels (continuous).
    glm::vec3 direction(float x, float y) const;
    // Projects a world point to pixel coordinates; false behind the eye.
    bool project(const glm::vec3& p, float& x, float& y) const;
};

CameraState cameraAt(const Scene& scene, float t, int width, int height);

struct ObjectState {
    glm::mat4 objectToWorld{1.0f};
    glm::mat4 worldToObject{1.0f};
    float scale = 1.0f;   // uniform
    glm::vec3 eye{0.0f};  // object space
};

ObjectState objectAt(const SceneObject& object, float t, const CameraState& camera);

// The camera's view direction in the object's space (unit): what a representation's range
// compares (its representative view's and a frame's), made the same way everywhere.
glm::vec3 viewForward(const ObjectState& state, const CameraState& camera);

// Fills the animated parameter block `program` expects (IrProgram::paramFloats floats).
void animatedParamsAt(const SceneObject& object, const IrProgram& program, float t,
                      std::vector<float>& block);

// All scene lights at time t, in the object's coordinates (indexed as the scene's lights).
void lightsAt(const Scene& scene, const ObjectState& object, float t,
              std::vector<LightSample>& out);

}  // namespace mpshade
