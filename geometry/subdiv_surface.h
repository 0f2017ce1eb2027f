// subdiv_surface.h -- subdivision surfaces: the exact limit surface of an OBJ control cage,
// evaluated with OpenSubdiv's Bfr (Catmull-Clark "catmark" or Loop).
//
// Charts: one per cage face whose parameterization is a single quad (catmark) or triangle
// (Loop). A catmark face with n != 4 sides is split by Bfr into n quad sub-faces, and each
// is a chart of its own. A Loop triangle's chart maps the unit square onto the triangle as
// (u, v) -> barycentric (u (1 - v), v) (collapsed along the v = 1 edge).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "geometry/surface_sample.h"

namespace mpshade {

enum class SubdivScheme { Catmark, Loop };

struct SubdivCage {
    std::vector<glm::vec3> positions;
    std::vector<int> faceSizes;    // vertices per face
    std::vector<int> faceIndices;  // zero-based, faceSizes.sum() entries
};

class SubdivSurface {
  public:
    // Builds the limit surface; throws InputError (naming `source`) for cages OpenSubdiv
    // cannot subdivide (e.g. non-triangles with Loop, or no valid face).
    SubdivSurface(const SubdivCage& cage, SubdivScheme scheme, const std::string& source);
    ~SubdivSurface();
    SubdivSurface(SubdivSurface&&) noexcept;
    SubdivSurface& operator=(SubdivSurface&&) noexcept;

    int chartCount() const;
    SurfaceSample evaluate(int chart, float u, float v) const;
    Bounds3 bounds() const;
    int tessellationRate(int chart) const { return 24; }
    // The cage face a chart belongs to.
    int chartFace(int chart) const;
    // Every cage edge is shared by exactly two faces: the surface bounds a solid.
    bool closed() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// Reads an OBJ control cage (v and f records; vt/vn are ignored for subdivision).
SubdivCage loadObjCage(const std::string& path);

}  // namespace mpshade
