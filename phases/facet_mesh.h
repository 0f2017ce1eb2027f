// facet_mesh.h -- the geometry of the static phase's product for one object (patent FIG. 4,
// claims 22-24): polygonal facets with shared vertices in fixed point, in the object's own
// coordinates, and per-vertex data for the dynamic phase.
//
// Fixed-point format: each vertex coordinate is a 16-bit unsigned integer q over the
// object's bounding box: object = origin + q * step, step = extent / 65535 per axis. The
// quantization error is at most step / 2 per axis (extent / 131070): 1/131070 of the
// object's size.
//
// A facet corner has two indices: its position (shared by every chart that meets there,
// so neighbouring grids are watertight under the warp) and its attributes (per chart,
// since (u, v), s, t and the n-tuple are the chart's own and may jump across a chart
// border).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "geometry/surface_sample.h"

namespace mpshade {

struct FixedPointFormat {
    glm::vec3 origin{0.0f};
    glm::vec3 step{1.0f};  // object units per quantum, per axis
    static constexpr int kBits = 16;
    static constexpr uint32_t kMax = (1u << kBits) - 1;

    static FixedPointFormat forBounds(const Bounds3& bounds);
    uint16_t quantize(float x, int axis) const;
    glm::vec3 dequantize(uint16_t x, uint16_t y, uint16_t z) const {
        return origin + step * glm::vec3(x, y, z);
    }
};

// Per-attribute-vertex data the dynamic part reads, structure of arrays. Geometry rows hold
// only what the dynamic program uses; channel rows hold the n-tuple.
struct VertexAttributes {
    enum Row {
        Px,
        Py,
        Pz,
        Nx,
        Ny,
        Nz,
        Ngx,
        Ngy,
        Ngz,
        dPdux,
        dPduy,
        dPduz,
        dPdvx,
        dPdvy,
        dPdvz,
        U,
        V,
        S,
        T,
        kGeometryRows
    };
    std::vector<std::vector<float>> rows;  // kGeometryRows + channels; unused rows empty
    size_t count = 0;
};

// A patch's facets: a contiguous facet range with an object-space bounding sphere and a
// cone containing its normals, so a frame can skip it whole (off screen, or facing away).
struct FacetCluster {
    uint32_t firstFacet = 0, facetCount = 0;
    glm::vec3 center{0.0f};
    float radius = 0.0f;
    glm::vec3 coneAxis{0.0f, 0.0f, 1.0f};
    float coneHalfAngle = 4.0f;  // radians; > pi: no useful cone
};

struct FacetMesh {
    FixedPointFormat format;
    // Shared positions, quantized, structure of arrays.
    std::vector<uint16_t> qx, qy, qz;
    // Per facet: three position indices and three attribute indices.
    std::vector<uint32_t> positionIndex;
    std::vector<uint32_t> attributeIndex;
    VertexAttributes attributes;
    std::vector<ChartPoint> attributeChartPoint;  // where each attribute vertex lies
    std::vector<FacetCluster> clusters;           // cover every facet, in order
    int channels = 0;                             // n-tuple rows in `attributes` (may be empty)

    size_t facetCount() const { return positionIndex.size() / 3; }
    size_t positionCount() const { return qx.size(); }
    size_t bytes() const;
};

}  // namespace mpshade
