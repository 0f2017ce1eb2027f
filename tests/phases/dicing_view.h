// dicing_view.h -- a camera and its dicing view for the tests of dicing and clipping.
#pragma once

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "phases/dicing.h"
#include "phases/fixed_point_warp.h"

namespace mpshade::test {

// A dicing view of a camera at `eye` looking at `target`, both in the object's own space
// (the object at the origin, unscaled), for an image `height` pixels tall with a 40 degree
// field of view.
struct View {
    CameraState camera;
    DicingView dicing;
    View(const glm::vec3& eye, const glm::vec3& target, int width, int height) {
        camera.eye = eye;
        camera.forward = glm::normalize(target - eye);
        camera.right = glm::normalize(glm::cross(camera.forward, glm::vec3(0, 1, 0)));
        camera.up = glm::cross(camera.right, camera.forward);
        camera.tanHalfFovY = std::tan(glm::radians(20.0f));
        camera.aspect = float(width) / float(height);
        camera.zNear = 0.01f;
        camera.zFar = 1000.0f;
        camera.width = width;
        camera.height = height;
        dicing.eye = eye;
        dicing.pixelsPerUnit = 0.5f * height / camera.tanHalfFovY;
        const float tx = camera.tanHalfFovY * camera.aspect, ty = camera.tanHalfFovY;
        dicing.fovSlack = 1.0f + tx * tx + ty * ty;
        dicing.nearDistance = camera.zNear;
        dicing.forward = camera.forward;
        dicing.halfDiagonalFov = std::atan(std::sqrt(tx * tx + ty * ty));
        dicing.projects = true;
        objectToScreen(glm::mat4(1.0f), camera, dicing.screen);
        dicing.nearW = camera.zNear;
    }
    bool project(const glm::vec3& p, glm::dvec2& out) const {
        double h[3];
        for (int r = 0; r < 3; ++r)
            h[r] = dicing.screen[r][0] * p.x + dicing.screen[r][1] * p.y +
                   dicing.screen[r][2] * p.z + dicing.screen[r][3];
        if (!(h[2] > 0.0)) return false;
        out = glm::dvec2(h[0] / h[2], h[1] / h[2]);
        return true;
    }
};

}  // namespace mpshade::test
