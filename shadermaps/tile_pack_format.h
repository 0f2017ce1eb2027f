// tile_pack_format.h -- the bytes of a store's pack (tile_store.h, docs/store.md), shared by
// the store's reads and writes and by its compaction: each tile a 48-byte header (magic, map
// digest, tile key, payload size, XXH3-64 of the payload) and its storage, then an index of
// (key, offset) and a footer (magic, count, index offset, index checksum). Private to the
// shadermaps library.
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "geometry/content_digest.h"

namespace mpshade::pack {

inline constexpr char kTileMagic[8] = {'M', 'P', 'S', 'T', 'I', 'L', 'E', '1'};
inline constexpr char kPackMagic[8] = {'M', 'P', 'S', 'P', 'A', 'C', 'K', '1'};

struct TileHeader {
    char magic[8];
    uint64_t mapHigh, mapLow, key, payloadBytes, checksum;
};
static_assert(sizeof(TileHeader) == 48);

struct IndexEntry {
    uint64_t key, offset;  // offset: of the tile's header, from the start of the pack
};
static_assert(sizeof(IndexEntry) == 16);

struct PackFooter {
    char magic[8];
    uint64_t count, indexOffset, indexChecksum;
};
static_assert(sizeof(PackFooter) == 32);

// A name in the same folder (so a rename stays on one file system) that no other writer, in
// this process or another, on this machine or another, picks.
std::string uniqueName();

// Reads exactly `bytes` at `offset`; false on a short read or an error.
bool readAt(int fd, void* to, size_t bytes, uint64_t offset);

// Writes a file under a temporary name, then renames it into place: readers see the whole
// file or none. `write` writes the contents and says whether it could; on failure nothing
// is left.
bool writeAtomically(const std::filesystem::path& path,
                     const std::function<bool(std::FILE*)>& write);
// The same for a file made of `pieces`, one after another.
bool writeAtomically(const std::filesystem::path& path,
                     std::span<const std::span<const unsigned char>> pieces);

// Whether a tile's header is one, of tile `key` of map `map` (its payload size and checksum
// are the caller's to check against what it reads).
bool headerNames(const TileHeader& header, const Digest128& map, uint64_t key);

// A pack's index, checked against its footer; false if the pack is damaged.
bool readIndex(int fd, uint64_t fileBytes, std::vector<IndexEntry>& entries);

// The footer of a pack whose index is `entries`, starting at `indexOffset`.
PackFooter footerFor(std::span<const IndexEntry> entries, uint64_t indexOffset);

inline std::span<const unsigned char> bytesOf(const void* p, size_t n) {
    return {static_cast<const unsigned char*>(p), n};
}

}  // namespace mpshade::pack
