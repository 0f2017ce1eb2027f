// analytic_shapes.h -- sphere, torus and plane: one chart each, evaluated in closed form.
//
// Coordinates are the object's own (y up). Parameterizations, all over [0,1]^2:
//   Sphere: u = longitude (phi = 2 pi u, from +x towards -z), v = latitude from the south
//           pole (v = 0, y = -r) to the north pole (v = 1).
//   Torus:  ring around the y axis; u goes around the ring, v around the tube (v = 0 on
//           the outer equator, v = 0.25 on top).
//   Plane:  in the xz-plane facing +y; u runs along +x, v along -z, so x = (u - 0.5) w and
//           z = (0.5 - v) d (this keeps cross(dPdu, dPdv) = +y, the facing direction).
#pragma once

#include "geometry/surface_sample.h"

namespace mpshade {

struct Sphere {
    float radius = 1.0f;  // > 0
    int chartCount() const { return 1; }
    SurfaceSample evaluate(int chart, float u, float v) const;
    Bounds3 bounds() const;
    int tessellationRate(int chart) const { return 96; }
};

struct Torus {
    float major = 1.0f;   // ring radius, > minor
    float minor = 0.25f;  // tube radius, > 0
    int chartCount() const { return 1; }
    SurfaceSample evaluate(int chart, float u, float v) const;
    Bounds3 bounds() const;
    int tessellationRate(int chart) const { return 96; }
};

struct Plane {
    float width = 1.0f;  // extent along x, > 0
    float depth = 1.0f;  // extent along z, > 0
    int chartCount() const { return 1; }
    // Inline: a floor's map fills evaluate it at every texel, where the call and the copy
    // of its result out of line had been a tenth of the fill (evaluateBatch's loop).
    SurfaceSample evaluate(int /*chart*/, float u, float v) const {
        SurfaceSample s;
        s.P = glm::vec3((u - 0.5f) * width, 0.0f, (0.5f - v) * depth);
        s.dPdu = glm::vec3(width, 0.0f, 0.0f);
        s.dPdv = glm::vec3(0.0f, 0.0f, -depth);
        s.N = s.Ng = glm::vec3(0.0f, 1.0f, 0.0f);
        s.s = u;
        s.t = v;
        return s;
    }
    Bounds3 bounds() const;
    int tessellationRate(int chart) const { return 1; }
};

}  // namespace mpshade
