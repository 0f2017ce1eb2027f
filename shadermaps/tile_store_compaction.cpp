// TileStore::compact: a map's packs merged into one (tile_store.h).
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <unordered_set>
#include <utility>

#include "geometry/content_digest.h"
#include "shadermaps/tile_pack_format.h"
#include "shadermaps/tile_store.h"

namespace mpshade {
namespace {

namespace fs = std::filesystem;
using pack::IndexEntry;
using pack::TileHeader;

// A tile's storage is a few kilobytes (a 16 x 16 tile of a few float channels); a header
// claiming more is damaged, not a reason to allocate.
constexpr uint64_t kMaxTileBytes = uint64_t{1} << 26;

// A pack being merged, open for reading while it is.
struct SourcePack {
    fs::path path;
    fs::file_time_type written;
    int fd = -1;
    std::vector<IndexEntry> entries;

    SourcePack() = default;
    SourcePack(SourcePack&& o) noexcept
        : path(std::move(o.path)),
          written(o.written),
          fd(std::exchange(o.fd, -1)),
          entries(std::move(o.entries)) {}
    SourcePack& operator=(SourcePack&& o) noexcept {
        std::swap(path, o.path);
        std::swap(written, o.written);
        std::swap(fd, o.fd);
        std::swap(entries, o.entries);
        return *this;
    }
    ~SourcePack() {
        if (fd >= 0) ::close(fd);
    }
};

// The map's packs whose index reads whole, newest first (ties by name, so every process
// orders them alike). Damaged ones are left for readers to count and remove.
std::vector<SourcePack> listPacks(const fs::path& folder) {
    std::vector<SourcePack> packs;
    std::error_code ec;
    for (const fs::directory_entry& f : fs::directory_iterator(folder, ec)) {
        if (f.path().extension() != ".pack") continue;
        SourcePack p;
        p.path = f.path();
        p.written = f.last_write_time(ec);
        p.fd = ::open(p.path.c_str(), O_RDONLY | O_CLOEXEC);
        struct stat st {};
        if (p.fd >= 0 && ::fstat(p.fd, &st) == 0 &&
            pack::readIndex(p.fd, static_cast<uint64_t>(st.st_size), p.entries))
            packs.push_back(std::move(p));
    }
    std::sort(packs.begin(), packs.end(), [](const SourcePack& a, const SourcePack& b) {
        return a.written != b.written ? a.written > b.written : a.path > b.path;
    });
    return packs;
}

// One tile of a source pack, checked as a read checks it (header, map, key, size, checksum).
bool readTile(const SourcePack& p, const IndexEntry& e, const Digest128& map, TileHeader& header,
              std::vector<unsigned char>& payload) {
    if (!pack::readAt(p.fd, &header, sizeof header, e.offset) ||
        !pack::headerNames(header, map, e.key) || header.payloadBytes > kMaxTileBytes)
        return false;
    payload.resize(header.payloadBytes);
    return pack::readAt(p.fd, payload.data(), payload.size(), e.offset + sizeof header) &&
           checksum64(payload.data(), payload.size()) == header.checksum;
}

}  // namespace

size_t TileStore::compact(const Digest128& map, size_t maxPacks) {
    flush();  // the packs written behind are merged too
    if (readOnly_.load(std::memory_order_relaxed)) return 0;
    const fs::path folder = mapFolder(map);
    std::error_code ec;
    if (!fs::is_directory(folder, ec)) return 0;
    const std::unique_ptr<FillLock> lock = lockFills(map);
    if (!lock) return 0;
    const std::vector<SourcePack> packs = listPacks(folder);
    if (packs.size() <= std::max<size_t>(maxPacks, 1)) return 0;
    // Each tile's newest copy that reads whole: a damaged one gives way to an older copy.
    const auto writeMerged = [&](std::FILE* f) {
        std::vector<IndexEntry> index;
        std::unordered_set<uint64_t> done;
        uint64_t offset = 0;
        TileHeader header{};
        std::vector<unsigned char> payload;
        for (const SourcePack& p : packs)
            for (const IndexEntry& e : p.entries) {
                if (done.count(e.key)) continue;
                if (!readTile(p, e, map, header, payload)) {
                    counters_.damaged.fetch_add(1, std::memory_order_relaxed);
                    continue;
                }
                if (std::fwrite(&header, sizeof header, 1, f) != 1 ||
                    (!payload.empty() && std::fwrite(payload.data(), payload.size(), 1, f) != 1))
                    return false;
                index.push_back({e.key, offset});
                offset += sizeof header + payload.size();
                done.insert(e.key);
            }
        const pack::PackFooter footer = pack::footerFor(index, offset);
        return (index.empty() ||
                std::fwrite(index.data(), sizeof(IndexEntry) * index.size(), 1, f) == 1) &&
               std::fwrite(&footer, sizeof footer, 1, f) == 1;
    };
    if (!pack::writeAtomically(folder / (pack::uniqueName() + ".pack"), writeMerged)) return 0;
    // Readers in this process find the merged pack (the newest) before the removed ones.
    for (const SourcePack& p : packs) ::unlink(p.path.c_str());
    refresh(map);
    return packs.size();
}

size_t TileStore::compactWritten(size_t maxPacks) {
    flush();
    std::vector<std::string> maps;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        maps.assign(written_.begin(), written_.end());
    }
    size_t removed = 0;
    for (const std::string& hex : maps) {
        Digest128 map;
        if (Digest128::fromHex(hex, map)) removed += compact(map, maxPacks);
    }
    return removed;
}

}  // namespace mpshade
