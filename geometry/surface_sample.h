// surface_sample.h -- what a surface reports at a point of its global parameterization.
#pragma once

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace mpshade {

// A point on a surface's global parameterization: chart index and (u, v) in [0,1]^2.
// Every surface type maps each of its charts onto [0,1]^2 without overlap (see
// docs/geometry.md for each type's charts).
struct ChartPoint {
    int chart = 0;
    float u = 0.0f;
    float v = 0.0f;
};

// Differential geometry at a chart point, all in the object's own coordinates.
// Orientation rule: dot(Ng, cross(dPdu, dPdv)) >= 0 wherever the cross product is not
// degenerate, except on meshes that supply vertex normals, where Ng is flipped into N's
// hemisphere. N and Ng are unit length and always agree in hemisphere.
struct SurfaceSample {
    glm::vec3 P{0.0f};
    glm::vec3 N{0.0f, 1.0f, 0.0f};   // shading normal (interpolated or analytic)
    glm::vec3 Ng{0.0f, 1.0f, 0.0f};  // geometric normal
    glm::vec3 dPdu{0.0f};
    glm::vec3 dPdv{0.0f};
    float s = 0.0f;  // texture coordinates: the mesh's own when it has them, else (u, v)
    float t = 0.0f;
};

// Axis-aligned bounds in object space.
struct Bounds3 {
    glm::vec3 lo{1e30f};
    glm::vec3 hi{-1e30f};
    void extend(const glm::vec3& p);
    void extend(const Bounds3& b);
    glm::vec3 center() const { return 0.5f * (lo + hi); }
    // Length of the diagonal; the "scene scale" tolerances are relative to.
    float diagonal() const;
    bool empty() const { return lo.x > hi.x; }
};

// Unit geometric normal from the derivatives, or `fallback` when they are parallel or zero.
glm::vec3 normalFromDerivatives(const glm::vec3& dPdu, const glm::vec3& dPdv,
                                const glm::vec3& fallback);

}  // namespace mpshade
