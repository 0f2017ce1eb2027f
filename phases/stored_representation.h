// stored_representation.h -- a built representation's facets as bytes, for the store
// (shadermaps/tile_store.h): what the static phase's dicing and vertex shading made
// (positions, facets, vertex attributes, clusters, counts), so a second run of the same
// frames reads them instead of dicing again. The shader map, kernels and options are not
// in it: the static phase sets them as it does for a representation it builds.
#pragma once

#include <span>
#include <vector>

#include "phases/object_representation.h"

namespace mpshade {

// The mesh, the patch counts and maxEdgePixels of `rep`.
std::vector<unsigned char> packRepresentation(const ObjectRepresentation& rep);

// Reads what packRepresentation() wrote into `rep`; false (and `rep` unusable) when the
// bytes are not such a record: every length is checked against the bytes left and every
// facet's indices against the vertices, so no record, damaged or made up, reads out of
// bounds.
bool unpackRepresentation(std::span<const unsigned char> bytes, ObjectRepresentation& rep);

}  // namespace mpshade
