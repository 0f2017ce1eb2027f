#include "scene/scene_state.h"

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/matrix.hpp>

namespace mpshade {

glm::vec3 CameraState::direction(float x, float y) const {
    const float sx = (2.0f * x / static_cast<float>(width) - 1.0f) * tanHalfFovY * aspect;
    const float sy = (1.0f - 2.0f * y / static_cast<float>(height)) * tanHalfFovY;
    return glm::normalize(forward + sx * right + sy * up);
}

bool CameraState::project(const glm::vec3& p, float& x, float& y) const {
    const glm::vec3 d = p - eye;
    const float z = glm::dot(d, forward);
    if (!(z > 0.0f)) return false;
    const float sx = glm::dot(d, right) / (z * tanHalfFovY * aspect);
    const float sy = glm::dot(d, up) / (z * tanHalfFovY);
    x = (sx + 1.0f) * 0.5f * static_cast<float>(width);
    y = (1.0f - sy) * 0.5f * static_cast<float>(height);
    return true;
}

CameraState cameraAt(const Scene& scene, float t, int width, int height) {
    const Camera& cam = scene.camera;
    CameraState c;
    c.eye = cam.eye.at(t);
    c.forward = glm::normalize(cam.target.at(t) - c.eye);
    glm::vec3 up = cam.up.at(t);
    glm::vec3 right = glm::cross(c.forward, up);
    if (!(glm::length(right) > 1e-6f)) {
        // Looking straight along `up`: any perpendicular will do.
        right = glm::cross(c.forward,
                           std::fabs(c.forward.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 0, 1));
    }
    c.right = glm::normalize(right);
    c.up = glm::cross(c.right, c.forward);
    c.tanHalfFovY = std::tan(glm::radians(cam.fovY) * 0.5f);
    c.aspect = static_cast<float>(width) / static_cast<float>(height);
    c.zNear = cam.zNear;
    c.zFar = cam.zFar;
    c.width = width;
    c.height = height;
    return c;
}

glm::vec3 viewForward(const ObjectState& state, const CameraState& camera) {
    return glm::normalize(glm::vec3(state.worldToObject * glm::vec4(camera.forward, 0.0f)));
}

ObjectState objectAt(const SceneObject& object, float t, const CameraState& camera) {
    const ObjectTransform& tr = object.transform;
    const glm::vec4 rot = tr.rotate.at(t);
    const glm::vec3 axis = glm::normalize(glm::vec3(rot));
    ObjectState s;
    s.scale = tr.scale.at(t);
    // Scale, then rotate, then translate.
    s.objectToWorld = glm::translate(glm::mat4(1.0f), tr.translate.at(t)) *
                      glm::rotate(glm::mat4(1.0f), glm::radians(rot.w), axis) *
                      glm::scale(glm::mat4(1.0f), glm::vec3(s.scale));
    s.worldToObject = glm::inverse(s.objectToWorld);
    s.eye = glm::vec3(s.worldToObject * glm::vec4(camera.eye, 1.0f));
    return s;
}

void animatedParamsAt(const SceneObject& object, const IrProgram& program, float t,
                      std::vector<float>& block) {
    block.assign(static_cast<size_t>(program.paramFloats), 0.0f);
    for (const AnimatedParam& ap : program.animatedParams) {
        for (const ParamValue& pv : object.params) {
            if (pv.name != ap.name) continue;
            const glm::vec3 v = pv.value.at(t);
            for (int k = 0; k < ap.components; ++k) block[static_cast<size_t>(ap.slot + k)] = v[k];
        }
    }
}

void lightsAt(const Scene& scene, const ObjectState& object, float t,
              std::vector<LightSample>& out) {
    out.clear();
    for (const Light& light : scene.lights) {
        LightSample s;
        s.kind = light.kind;
        s.color = light.color.at(t) * light.intensity.at(t);
        if (light.kind == LightKind::Point) {
            s.position = glm::vec3(object.worldToObject * glm::vec4(light.position.at(t), 1.0f));
            // Distances shrink by 1/scale in object space; keep the world's falloff.
            s.color /= object.scale * object.scale;
        } else if (light.kind == LightKind::Distant) {
            const glm::vec3 travel = light.direction.at(t);
            s.toLight = glm::normalize(glm::vec3(object.worldToObject * glm::vec4(-travel, 0.0f)));
        }
        out.push_back(s);
    }
}

}  // namespace mpshade
