#include "geometry/polygon_mesh.h"

#include <map>

#include <glm/geometric.hpp>

namespace mpshade {

bool cageIsClosed(const std::vector<int>& faceSizes, const std::vector<int>& faceIndices) {
    std::map<std::pair<int, int>, int> edges;
    size_t first = 0;
    for (int size : faceSizes) {
        for (int k = 0; k < size; ++k) {
            const int a = faceIndices[first + static_cast<size_t>(k)];
            const int b = faceIndices[first + static_cast<size_t>((k + 1) % size)];
            ++edges[{std::min(a, b), std::max(a, b)}];
        }
        first += static_cast<size_t>(size);
    }
    for (const auto& [edge, count] : edges)
        if (count != 2) return false;
    return !edges.empty();
}

PolygonMesh::PolygonMesh(PolygonMeshData data) : data_(std::move(data)) {
    {
        std::vector<int> indices;
        for (const ObjCorner& c : data_.corners) indices.push_back(c.position);
        closed_ = cageIsClosed(data_.faceSizes, indices);
    }
    size_t first = 0;
    auto area2 = [&](const ObjCorner& a, const ObjCorner& b, const ObjCorner& c) {
        const glm::vec3 &pa = data_.positions[a.position], &pb = data_.positions[b.position],
                        &pc = data_.positions[c.position];
        return glm::length(glm::cross(pb - pa, pc - pa));
    };
    for (int size : data_.faceSizes) {
        const ObjCorner* c = &data_.corners[first];
        first += static_cast<size_t>(size);
        if (size == 4) {
            if (area2(c[0], c[1], c[2]) + area2(c[0], c[2], c[3]) > 0.0f)
                charts_.push_back({{c[0], c[1], c[2], c[3]}, true});
            else
                ++dropped_;
            continue;
        }
        for (int k = 1; k + 1 < size; ++k) {
            if (area2(c[0], c[k], c[k + 1]) > 0.0f)
                charts_.push_back({{c[0], c[k], c[k + 1], c[k + 1]}, false});
            else
                ++dropped_;
        }
    }
    for (const auto& p : data_.positions) bounds_.extend(p);
}

SurfaceSample PolygonMesh::evaluate(int chart, float u, float v) const {
    const Chart& c = charts_[static_cast<size_t>(chart)];
    // Corner weights and their u/v derivatives.
    float w[4], wu[4], wv[4];
    if (c.quad) {
        w[0] = (1 - u) * (1 - v), w[1] = u * (1 - v), w[2] = u * v, w[3] = (1 - u) * v;
        wu[0] = -(1 - v), wu[1] = 1 - v, wu[2] = v, wu[3] = -v;
        wv[0] = -(1 - u), wv[1] = -u, wv[2] = u, wv[3] = 1 - u;
    } else {
        const float b1 = u * (1 - v), b2 = v;
        w[0] = 1 - b1 - b2, w[1] = b1, w[2] = b2, w[3] = 0;
        wu[0] = -(1 - v), wu[1] = 1 - v, wu[2] = 0, wu[3] = 0;
        wv[0] = u - 1, wv[1] = -u, wv[2] = 1, wv[3] = 0;
    }
    const int n = c.quad ? 4 : 3;
    SurfaceSample s;
    glm::vec3 N(0.0f);
    glm::vec2 st(0.0f);
    bool hasN = true, hasT = true;
    for (int k = 0; k < n; ++k) {
        const ObjCorner& k_ = c.corner[k];
        const glm::vec3& p = data_.positions[k_.position];
        s.P += w[k] * p;
        s.dPdu += wu[k] * p;
        s.dPdv += wv[k] * p;
        if (k_.normal >= 0)
            N += w[k] * data_.normals[k_.normal];
        else
            hasN = false;
        if (k_.texcoord >= 0)
            st += w[k] * data_.texcoords[k_.texcoord];
        else
            hasT = false;
    }
    // The face's own edges give Ng even where a triangle chart collapses (v = 1).
    const glm::vec3& p0 = data_.positions[c.corner[0].position];
    const glm::vec3& p1 = data_.positions[c.corner[1].position];
    const glm::vec3& p2 = data_.positions[c.corner[2].position];
    glm::vec3 faceNormal = normalFromDerivatives(p1 - p0, p2 - p0, glm::vec3(0, 1, 0));
    s.Ng = c.quad ? normalFromDerivatives(s.dPdu, s.dPdv, faceNormal) : faceNormal;
    s.N = s.Ng;
    if (hasN && glm::dot(N, N) > 0.0f) {
        s.N = glm::normalize(N);
        if (glm::dot(s.N, s.Ng) < 0.0f) s.Ng = -s.Ng;  // N and Ng share a hemisphere
    }
    s.s = hasT ? st.x : u;
    s.t = hasT ? st.y : v;
    return s;
}

}  // namespace mpshade
