// ray_scene.h -- Embree ray queries against one surface, in the surface's own coordinates,
// reporting hits as exact points of the surface's global parameterization.
//
// Parametric surfaces are traced as a fine triangle tessellation whose vertices lie on the
// exact surface, and each hit is then refined by Newton iteration on the exact surface
// (Bfr limit evaluation for subdivision surfaces), so the reported (chart, u, v) and t lie
// on the true surface to float precision. Where Newton cannot converge (singular charts,
// grazing silhouettes) the tessellation hit is kept, and the hit point is moved onto the
// surface at the interpolated (chart, u, v); that error is bounded by the tessellation's
// chord sag (docs/geometry.md). Point clouds are traced as Embree oriented discs.
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <vector>

#include <embree3/rtcore.h>
#include <glm/vec3.hpp>

#include "geometry/surface.h"

namespace mpshade {

// The process-wide Embree device (thread safe, created on first use).
RTCDevice embreeDevice();

// Sets flush-to-zero and denormals-are-zero on the calling thread, as Embree recommends.
void enableFlushToZero();

struct SurfaceHit {
    ChartPoint at;
    float t = 0.0f;        // ray parameter of the hit: P = org + t * dir
    bool refined = false;  // Newton converged on the exact surface
};

// Built on first use (any query, scene() or triangleCount()), once, by whichever thread
// asks first while the others wait: a run whose shader maps all come from a store never
// traces an occlusion ray, and the tessellation (about 0.1 s for a subdivision vase) was
// most of its set-up. The charts are tessellated in parallel.
class SurfaceRayScene {
  public:
    // The surface must outlive this object.
    explicit SurfaceRayScene(const Surface& surface);
    ~SurfaceRayScene();
    SurfaceRayScene(const SurfaceRayScene&) = delete;
    SurfaceRayScene& operator=(const SurfaceRayScene&) = delete;

    RTCScene scene() const {
        build();
        return scene_;
    }
    const Surface& surface() const { return surface_; }

    // Turns an Embree hit on scene() (geomID, primID, barycentrics) of the object-space ray
    // org + t dir into an exact hit. Returns false if refinement moves it outside
    // [tnear, tfar].
    bool resolveHit(unsigned geomID, unsigned primID, float bu, float bv, float tHit,
                    const glm::vec3& org, const glm::vec3& dir, SurfaceHit& hit) const;

    // Nearest hit along org + t dir, t in [tnear, tfar]; object space.
    bool intersect(const glm::vec3& org, const glm::vec3& dir, float tnear, float tfar,
                   SurfaceHit& hit) const;
    // Any hit along each of n segments (shadow and occlusion rays), origins and directions
    // as rows (x, y, z: 3 x n floats each), t in [tnear, tfar]; a ray whose `active` entry
    // is 0 is not traced (active may be null: all). Writes blocked[i] = 1 where ray i hits.
    // Rays given in coherent order (one direction of a pattern from neighbouring points)
    // are traced as a stream, which Embree takes in packets: ambient occlusion's rays cost
    // a third less than one by one. A ray that provably cannot meet the surface is answered
    // without Embree (escapes()): on a plane or a sphere, every ray of a point's
    // hemisphere of occlusion.
    void occluded(const float* const org[3], const float* const dir[3], const uint8_t* active,
                  int n, float tnear, float tfar, uint8_t* blocked) const;

    // True when the ray org + t dir, t >= 0, cannot meet the surface's tessellation, by its
    // shape alone: a plane (y = 0) with org off it and dir not toward it; a sphere with org
    // outside it by more than its vertices' rounding and dir not toward its centre (the ray
    // then only moves away from the centre, and the tessellation lies within the sphere).
    // False whenever this is not certain, and for every other surface.
    bool escapes(const glm::vec3& org, const glm::vec3& dir) const;

    size_t triangleCount() const {
        build();
        return triChart_.size();
    }
    // Whether the scene has been built (by a query, or by asking for it ahead).
    bool built() const { return builtFlag_.load(std::memory_order_acquire); }

  private:
    void build() const {
        std::call_once(built_, [this] { buildNow(); });
    }
    void buildNow() const;
    unsigned attachTessellation(RTCDevice device) const;  // the triangles' geometry id

    const Surface& surface_;
    // Set once by build(), read only after it.
    mutable std::once_flag built_;
    mutable std::atomic<bool> builtFlag_{false};
    mutable RTCScene scene_ = nullptr;
    mutable unsigned triGeom_ = RTC_INVALID_GEOMETRY_ID;
    mutable unsigned discGeom_ = RTC_INVALID_GEOMETRY_ID;
    mutable std::vector<int> triChart_;       // chart of each triangle
    mutable std::vector<unsigned> triIndex_;  // 3 vertex indices per triangle
    mutable std::vector<float> vertexUV_;     // (u, v) per tessellation vertex
};

}  // namespace mpshade
