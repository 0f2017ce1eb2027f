#include "app/store_export.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <map>
#include <set>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>

#include "app/oiio_loader.h"
#include "app/output_files.h"
#include "geometry/error.h"
#include "shadermaps/half_float.h"
#include "shadermaps/shader_map.h"

namespace mpshade {
namespace {

// One level of a chart as floats: the channels, then `filled`.
struct LevelImage {
    int size = 0;
    std::vector<float> texels;
};

}  // namespace

MapExport exportStoredMap(TileStore& store, const StoredMapSummary& map,
                          const std::filesystem::path& dir, int maxSize) {
    const StoredMapInfo& info = map.info;
    const int channels = static_cast<int>(info.channelNames.size());
    MapExport result;
    const auto powerOfTwo = [](int v) { return v > 0 && (v & (v - 1)) == 0; };
    if (channels < 1 || channels > 64 || !powerOfTwo(info.resolution) ||
        info.resolution > (1 << 20) || !powerOfTwo(info.tileSize) || info.tileSize > 1024 ||
        info.border < 1 || info.border > info.tileSize)
        throw InputError(
            {(store.root() / TileStore::kTilesFolder / map.digest.hex() / "map.json").string(), 0,
             0, ""},
            "this stored map's description is damaged or not mpshade's");
    int levels = 0;
    for (int r = info.resolution; r >= 1; r >>= 1) ++levels;
    int widest = 0;  // the finest level at most maxSize wide
    while ((info.resolution >> widest) > maxSize) ++widest;
    // The stored tiles by chart, as the packs' indices list them (only those are read).
    std::map<uint32_t, std::set<uint64_t>> charts;
    for (uint64_t key : store.storedKeys(map.digest))
        charts[static_cast<uint32_t>(key >> 37)].insert(key);
    const int T = info.tileSize, border = info.border, stride = T + 2 * border;
    const size_t tileBytes = static_cast<size_t>(stride) * stride * channels *
                             (info.halfPrecision ? sizeof(uint16_t) : sizeof(float));
    std::vector<unsigned char> tile(tileBytes);
    const int outChannels = channels + 1;
    for (const auto& [chart, stored] : charts) {
        // From the finest level with a stored tile, or the widest allowed if finer.
        int finest = levels - 1;
        for (uint64_t key : stored) finest = std::min(finest, static_cast<int>((key >> 32) & 31));
        finest = std::max(finest, widest);
        result.finestLevel = std::max(result.finestLevel, finest);
        std::vector<LevelImage> images;
        for (int level = finest; level < levels; ++level) {
            LevelImage image;
            image.size = info.resolution >> level;
            image.texels.assign(static_cast<size_t>(image.size) * image.size * outChannels, 0.0f);
            const int tiles = (image.size + T - 1) / T;
            for (int ty = 0; ty < tiles; ++ty)
                for (int tx = 0; tx < tiles; ++tx) {
                    const TileKey key{chart, static_cast<uint16_t>(level),
                                      static_cast<uint16_t>(tx), static_cast<uint16_t>(ty)};
                    if (!stored.count(key.packed()) ||
                        !store.read(map.digest, key.packed(), tile)) {
                        ++result.tilesMissing;
                        continue;
                    }
                    ++result.tilesRead;
                    for (int j = ty * T; j < std::min(image.size, (ty + 1) * T); ++j)
                        for (int i = tx * T; i < std::min(image.size, (tx + 1) * T); ++i) {
                            const size_t at = (static_cast<size_t>(j - ty * T + border) * stride +
                                               static_cast<size_t>(i - tx * T + border)) *
                                              channels;
                            float* out = &image.texels[(static_cast<size_t>(j) * image.size + i) *
                                                       outChannels];
                            for (int c = 0; c < channels; ++c) {
                                if (info.halfPrecision) {
                                    uint16_t h;
                                    std::memcpy(&h, tile.data() + (at + c) * sizeof h, sizeof h);
                                    out[c] = halfToFloat(h);
                                } else {
                                    std::memcpy(&out[c], tile.data() + (at + c) * sizeof(float),
                                                sizeof(float));
                                }
                            }
                            out[channels] = 1.0f;
                        }
                }
            images.push_back(std::move(image));
        }
        const std::filesystem::path path = dir / fmt::format("chart_{:04d}.exr", chart);
        // Tiled and mip-mapped by OpenImageIO (oiio_plugin.h).
        std::vector<std::string> names = info.channelNames;
        names.emplace_back("filled");
        std::vector<const char*> channelNames;
        for (const std::string& name : names) channelNames.push_back(name.c_str());
        std::vector<int> sizes;
        std::vector<const float*> levelTexels;
        for (const auto& level : images) {
            sizes.push_back(level.size);
            levelTexels.push_back(level.texels.data());
        }
        const char* attributeNames[] = {"mpshade:object", "mpshade:shader"};
        const char* attributeValues[] = {info.object.c_str(), info.shader.c_str()};
        const MpshadeMipmappedExr exr{static_cast<int>(levelTexels.size()),
                                      sizes.data(),
                                      levelTexels.data(),
                                      outChannels,
                                      channelNames.data(),
                                      std::min(T, images[0].size),
                                      finest,
                                      2,
                                      attributeNames,
                                      attributeValues};
        writeAtomically(path, [&](const std::string& temporary) {
            char error[512] = "";
            if (!oiioPlugin().writeMipmappedExr(temporary.c_str(), &exr, error, sizeof error))
                throw std::runtime_error(error);
        });
        ++result.charts;
    }
    return result;
}

}  // namespace mpshade
