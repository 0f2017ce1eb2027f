#include "shadermaps/tile_pack_format.h"

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>

#include "geometry/content_digest.h"

namespace mpshade::pack {

std::string uniqueName() {
    static std::atomic<uint64_t> counter{0};
    char host[64] = "host";
    ::gethostname(host, sizeof host - 1);
    host[sizeof host - 1] = '\0';
    char name[160];
    std::snprintf(name, sizeof name, "%s.%ld.%llx.%llu", host, static_cast<long>(::getpid()),
                  static_cast<unsigned long long>(
                      std::chrono::steady_clock::now().time_since_epoch().count()),
                  static_cast<unsigned long long>(counter.fetch_add(1)));
    return name;
}

bool readAt(int fd, void* to, size_t bytes, uint64_t offset) {
    auto* p = static_cast<unsigned char*>(to);
    while (bytes > 0) {
        const ssize_t got = ::pread(fd, p, bytes, static_cast<off_t>(offset));
        if (got <= 0) return false;
        p += got;
        bytes -= static_cast<size_t>(got);
        offset += static_cast<uint64_t>(got);
    }
    return true;
}

bool writeAtomically(const std::filesystem::path& path,
                     const std::function<bool(std::FILE*)>& write) {
    const std::filesystem::path temporary = path.string() + "." + uniqueName() + ".tmp";
    std::FILE* f = std::fopen(temporary.c_str(), "wb");
    if (!f) return false;
    bool ok = write(f);
    ok = (std::fclose(f) == 0) && ok;
    ok = ok && std::rename(temporary.c_str(), path.c_str()) == 0;
    if (!ok) ::unlink(temporary.c_str());
    return ok;
}

bool writeAtomically(const std::filesystem::path& path,
                     std::span<const std::span<const unsigned char>> pieces) {
    return writeAtomically(path, [&](std::FILE* f) {
        for (const auto& piece : pieces)
            if (!piece.empty() && std::fwrite(piece.data(), 1, piece.size(), f) != piece.size())
                return false;
        return true;
    });
}

bool headerNames(const TileHeader& header, const Digest128& map, uint64_t key) {
    return std::memcmp(header.magic, kTileMagic, sizeof kTileMagic) == 0 &&
           header.mapHigh == map.high && header.mapLow == map.low && header.key == key;
}

bool readIndex(int fd, uint64_t fileBytes, std::vector<IndexEntry>& entries) {
    PackFooter footer{};
    if (fileBytes < sizeof footer ||
        !readAt(fd, &footer, sizeof footer, fileBytes - sizeof footer) ||
        std::memcmp(footer.magic, kPackMagic, sizeof kPackMagic) != 0 ||
        footer.count > (fileBytes / sizeof(TileHeader)) ||
        footer.indexOffset + footer.count * sizeof(IndexEntry) + sizeof footer != fileBytes)
        return false;
    entries.resize(footer.count);
    return readAt(fd, entries.data(), entries.size() * sizeof(IndexEntry), footer.indexOffset) &&
           checksum64(entries.data(), entries.size() * sizeof(IndexEntry)) == footer.indexChecksum;
}

PackFooter footerFor(std::span<const IndexEntry> entries, uint64_t indexOffset) {
    PackFooter footer{};
    std::memcpy(footer.magic, kPackMagic, sizeof kPackMagic);
    footer.count = entries.size();
    footer.indexOffset = indexOffset;
    footer.indexChecksum = checksum64(entries.data(), entries.size() * sizeof(IndexEntry));
    return footer;
}

}  // namespace mpshade::pack
