// store_export.h -- a stored shader map as images: per chart, its levels as one tiled,
// mip-mapped OpenEXR whose channels are the n-tuple's (named as `factor` names them) and a
// `filled` channel, 1 where the texel's tile is in the store and 0 where it is not (those
// texels are 0, not invented). Readable by oiiotool, maketx's readers and any EXR viewer.
#pragma once

#include <filesystem>
#include <string>

#include "shadermaps/tile_store.h"

namespace mpshade {

struct MapExport {
    int charts = 0;       // files written
    int finestLevel = 0;  // the level each file starts at (its first MIP level)
    uint64_t tilesRead = 0, tilesMissing = 0;
};

// Writes DIR/chart_NNNN.exr for each chart of `map` with at least one stored tile; the
// finest level written is the finest whose side is at most `maxSize` texels. Throws
// OutputError when a file cannot be written.
MapExport exportStoredMap(TileStore& store, const StoredMapSummary& map,
                          const std::filesystem::path& dir, int maxSize);

}  // namespace mpshade
