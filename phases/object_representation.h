// object_representation.h -- what the static phase hands the dynamic phase for one
// object: the patent's intermediate representation (FIG. 2, 208) with its data block
// (FIG. 4, 410; claim 25).
//
//   * Combined (FIG. 4, claims 21-26): facets with edges under P/2 at the representative
//     view carrying the n-tuple per vertex.
//   * Separate (FIG. 5, claims 5-9): facets only as fine as the geometric error allows
//     (1/4 pixel over the range), and a shader map holding the n-tuple, probed per
//     shading point. The map outlives the facets: when the object is diced again its
//     tiles are kept, unless the static part depends on the view.
//
// Read-only once built: the dynamic phase only reads it, so frames may share it.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "phases/facet_mesh.h"
#include "scene/scene.h"
#include "shadermaps/shader_map.h"
#include "shading/interpreter.h"

namespace mpshade {

// A number no other representation made in this process has: the dynamic phase knows by it
// that a frame draws the very representation an earlier one did.
uint64_t newRepresentationSerial();

struct ObjectRepresentation {
    uint64_t serial = newRepresentationSerial();
    Representation kind = Representation::Facets;  // Facets or ShaderMap, never Auto
    std::string reason;                            // why this kind

    // The data block.
    glm::vec3 representativeEye{0.0f};                   // object space
    glm::vec3 representativeForward{0.0f, 0.0f, -1.0f};  // object space, unit
    glm::vec3 center{0.0f};  // object space: the centre the range is measured from
    RangeOptions range;
    bool frustumCulled = false;  // patches outside the range's views were dropped
    int imageHeight = 0;         // pixels: the image the facets were diced for
    // Combined: the projected edge length (pixels) beyond which the facets are diced again:
    // P/2, or a little over the longest edge they had at the representative view if that
    // was more (the dicing survey measures between grid points).
    float maxEdgePixels = 0.0f;
    // The dynamic shader (S_d) and what it reads of the facets.
    std::shared_ptr<const ShaderKernel> dynamicKernel;
    std::vector<int> geometryRows;  // VertexAttributes rows (P and I come from the facet)
    bool opaque = true;             // Oi is the constant 1
    bool closed = false;            // the surface bounds a solid: back faces are hidden

    // The intermediate representation.
    FacetMesh mesh;                  // with Facets, the n-tuple in mesh.attributes
    std::shared_ptr<ShaderMap> map;  // with ShaderMap

    // What dicing did, in patches (charts split for size).
    int charts = 0, patches = 0, culledPatches = 0, frustumCulledPatches = 0, cappedPatches = 0;

    // Whether a viewpoint (object space) is inside the range: distance within the factor
    // and direction around the centre within the angle, and, if patches were frustum
    // culled, the view direction within the angle too.
    bool inRange(const glm::vec3& eye, const glm::vec3& forward) const;
    // The geometric fiducials of a view (Lengyel and Snyder 1997, sec. 4: how far the view
    // moved from the representative one) against the range: the first that is beyond its
    // threshold, or none.
    struct RangeCheck {
        enum Fiducial { None, ViewDirection, Distance, AngleAround } fiducial = None;
        float measured = 0.0f, threshold = 0.0f;  // degrees, or the distance ratio
    };
    RangeCheck checkRange(const glm::vec3& eye, const glm::vec3& forward) const;
    // The same for any representative view: `range` around `center`, from representativeEye
    // looking along representativeForward (object space, unit), its patches frustum culled or
    // not.
    static RangeCheck checkRange(const RangeOptions& range, const glm::vec3& center,
                                 const glm::vec3& representativeEye,
                                 const glm::vec3& representativeForward, bool frustumCulled,
                                 const glm::vec3& eye, const glm::vec3& forward);
    // Bytes of the facets and their attributes (the map is counted apart: it is shared).
    size_t bytes() const { return mesh.bytes(); }
};

// A shader-map tile some frame asked for, of object `object`'s map.
struct TileRequest {
    uint32_t object = 0;
    TileKey key;
};

// Sorts requests by object, then key, and drops repeats.
void sortUniqueTiles(std::vector<TileRequest>& tiles);

}  // namespace mpshade
