// polygon_mesh.h -- polygon meshes from OBJ files, and the OBJ reader itself.
//
// Charts: a triangle is one chart, mapped from the unit square as barycentric
// (u (1 - v), v) over corners (0, 1, 2); a quad is one bilinear chart over corners
// (0, 1, 2, 3); an n-gon (n > 4) is fanned from its first corner into n - 2 triangle
// charts. Zero-area faces are dropped (they can be neither seen nor shaded).
// s, t come from the OBJ's vt when the face has them, else (u, v); N from vn when
// present, else Ng.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "geometry/surface_sample.h"

namespace mpshade {

struct ObjCorner {
    int position = -1;  // zero-based; -1 = absent
    int texcoord = -1;
    int normal = -1;
};

struct PolygonMeshData {
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;
    std::vector<glm::vec2> texcoords;
    std::vector<int> faceSizes;
    std::vector<ObjCorner> corners;  // faceSizes.sum() entries
};

// Reads the v/vt/vn/f records of an OBJ file (o, g, s, usemtl, mtllib, l and comments are
// skipped). Throws InputError with file:line:column for anything malformed: bad numbers,
// NaN/Inf, out-of-range or zero indices, faces with fewer than 3 corners, an empty mesh.
PolygonMeshData readObjPolygons(const std::string& path);

class PolygonMesh {
  public:
    explicit PolygonMesh(PolygonMeshData data);

    int chartCount() const { return static_cast<int>(charts_.size()); }
    SurfaceSample evaluate(int chart, float u, float v) const;
    Bounds3 bounds() const { return bounds_; }
    int tessellationRate(int chart) const { return 1; }
    int droppedFaces() const { return dropped_; }
    bool closed() const { return closed_; }

  private:
    struct Chart {
        std::array<ObjCorner, 4> corner;
        bool quad;
    };
    PolygonMeshData data_;
    std::vector<Chart> charts_;
    Bounds3 bounds_;
    int dropped_ = 0;
    bool closed_ = false;
};

// Whether every edge of a polygon mesh is shared by exactly two faces.
bool cageIsClosed(const std::vector<int>& faceSizes, const std::vector<int>& faceIndices);

}  // namespace mpshade
