#include "shadermaps/tile_store.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/uio.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>

#include <nlohmann/json.hpp>

#include "geometry/error.h"
#include "shadermaps/tile_pack_format.h"

namespace mpshade {
namespace {

namespace fs = std::filesystem;
using pack::bytesOf;
using pack::footerFor;
using pack::headerNames;
using pack::IndexEntry;
using pack::kPackMagic;
using pack::kTileMagic;
using pack::PackFooter;
using pack::readAt;
using pack::readIndex;
using pack::TileHeader;
using pack::uniqueName;
using pack::writeAtomically;
using Clock = std::chrono::steady_clock;

// Packs a reader keeps open at most; beyond, a read opens and closes its pack.
constexpr int kOpenPacks = 256;
std::atomic<int> openPacks{0};

}  // namespace

struct TileStore::Pack {
    fs::path path;
    fs::file_time_type written;
    int fd = -1;  // kept open once read (at most kOpenPacks across packs)
    ~Pack() {
        if (fd >= 0) {
            ::close(fd);
            openPacks.fetch_sub(1);
        }
    }
};

// What a map's packs hold: per key, where its copies are, newest pack first.
struct TileStore::MapIndex {
    struct Copy {
        Pack* pack;
        uint64_t offset;
    };
    std::shared_mutex mutex;
    std::map<std::string, std::unique_ptr<Pack>> packs;  // by file name
    std::unordered_map<uint64_t, std::vector<Copy>> copies;

    void add(Pack* pack, std::span<const IndexEntry> entries) {
        for (const IndexEntry& e : entries) {
            std::vector<Copy>& c = copies[e.key];
            c.push_back({pack, e.offset});
            std::stable_sort(c.begin(), c.end(), [](const Copy& a, const Copy& b) {
                return a.pack->written > b.pack->written;
            });
        }
    }
};

fs::path defaultStoreFolder() {
    if (const char* s = std::getenv("MPSHADE_STORE"); s && *s) return s;
    if (const char* c = std::getenv("XDG_CACHE_HOME"); c && *c)
        return fs::path(c) / "mpshade" / "store";
    if (const char* h = std::getenv("HOME"); h && *h)
        return fs::path(h) / ".cache" / "mpshade" / "store";
    return {};
}

TileStore::TileStore(fs::path root) : root_(std::move(root)) {
    std::error_code ec;
    fs::create_directories(root_ / kTilesFolder, ec);
    if (ec || !fs::is_directory(root_ / kTilesFolder))
        throw InputError({root_.string(), 0, 0, ""},
                         "cannot use this folder as a shader-map store (" +
                             (ec ? ec.message() : "not a folder") + ")");
}

fs::path TileStore::mapFolder(const Digest128& map) const {
    return root_ / kTilesFolder / map.hex();
}

void TileStore::warnOnce(const std::string& message) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (warned_) return;
    warned_ = true;
    std::fprintf(stderr,
                 "mpshade: warning: shader-map store %s: %s; going on without writing to it\n",
                 root_.c_str(), message.c_str());
}

// Adds the packs not seen yet; a pack whose index is damaged is removed.
void TileStore::scan(const Digest128& map, MapIndex& index) {
    std::error_code ec;
    const fs::path folder = mapFolder(map);
    for (const fs::directory_entry& f : fs::directory_iterator(folder, ec)) {
        const std::string name = f.path().filename().string();
        if (f.path().extension() != ".pack" || index.packs.count(name)) continue;
        const int fd = ::open(f.path().c_str(), O_RDONLY | O_CLOEXEC);
        if (fd < 0) continue;  // removed meanwhile
        struct stat st {};
        std::vector<IndexEntry> entries;
        if (::fstat(fd, &st) != 0 || !readIndex(fd, static_cast<uint64_t>(st.st_size), entries)) {
            ::close(fd);
            counters_.damaged.fetch_add(1, std::memory_order_relaxed);
            ::unlink(f.path().c_str());
            continue;
        }
        auto pack = std::make_unique<Pack>();
        pack->path = f.path();
        pack->written = f.last_write_time(ec);
        if (openPacks.fetch_add(1) < kOpenPacks) {
            pack->fd = fd;
        } else {
            openPacks.fetch_sub(1);
            ::close(fd);
        }
        index.add(pack.get(), entries);
        index.packs.emplace(name, std::move(pack));
    }
}

std::shared_ptr<TileStore::MapIndex> TileStore::indexOf(const Digest128& map) {
    std::shared_ptr<MapIndex> index;
    std::unique_lock<std::shared_mutex> scanning;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        std::shared_ptr<MapIndex>& slot = indices_[map.hex()];
        if (slot) return slot;
        // Published locked: another thread asking for it waits for the first scan.
        slot = std::make_shared<MapIndex>();
        scanning = std::unique_lock<std::shared_mutex>(slot->mutex);
        index = slot;
    }
    scan(map, *index);
    return index;
}

bool TileStore::read(const Digest128& map, uint64_t key, std::span<unsigned char> out) {
    const std::shared_ptr<MapIndex> index = indexOf(map);
    // The newest few copies (two processes that filled a tile at once each wrote one).
    std::array<MapIndex::Copy, 4> copies;
    size_t count = 0;
    {
        std::shared_lock<std::shared_mutex> lock(index->mutex);
        const auto it = index->copies.find(key);
        if (it != index->copies.end())
            for (const MapIndex::Copy& c : it->second)
                if (count < copies.size()) copies[count++] = c;
    }
    for (size_t k = 0; k < count; ++k) {
        const MapIndex::Copy& copy = copies[k];
        int fd = copy.pack->fd;
        const bool transient = fd < 0;
        if (transient) fd = ::open(copy.pack->path.c_str(), O_RDONLY | O_CLOEXEC);
        if (fd < 0) continue;  // removed by a clean-up: another copy, or missing
        TileHeader header{};
        iovec parts[2] = {{&header, sizeof header}, {out.data(), out.size()}};
        const ssize_t got = ::preadv(fd, parts, 2, static_cast<off_t>(copy.offset));
        if (transient) ::close(fd);
        if (got == static_cast<ssize_t>(sizeof header + out.size()) &&
            headerNames(header, map, key) && header.payloadBytes == out.size() &&
            checksum64(out.data(), out.size()) == header.checksum) {
            counters_.loaded.fetch_add(1, std::memory_order_relaxed);
            return true;
        }
        // Damaged (a disk error) or of another size: never read, filled again.
        counters_.damaged.fetch_add(1, std::memory_order_relaxed);
    }
    return false;
}

std::vector<uint64_t> TileStore::storedKeys(const Digest128& map) {
    const std::shared_ptr<MapIndex> index = indexOf(map);
    std::shared_lock<std::shared_mutex> lock(index->mutex);
    std::vector<uint64_t> keys;
    for (const auto& [key, copies] : index->copies) keys.push_back(key);
    std::sort(keys.begin(), keys.end());
    return keys;
}

TileStore::FillLock::~FillLock() {
    ::flock(fd_, LOCK_UN);
    ::close(fd_);
}

std::unique_ptr<TileStore::FillLock> TileStore::lockFills(const Digest128& map) {
    const fs::path folder = mapFolder(map);
    std::error_code ec;
    fs::create_directories(folder, ec);
    const int fd = ::open((folder / "fill.lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) return nullptr;
    while (::flock(fd, LOCK_EX) != 0) {
        if (errno != EINTR) {
            ::close(fd);
            return nullptr;
        }
    }
    return std::make_unique<FillLock>(fd);
}

bool TileStore::refresh(const Digest128& map) {
    const std::shared_ptr<MapIndex> index = indexOf(map);
    std::unique_lock<std::shared_mutex> lock(index->mutex);
    // Always listed (the folder's time may not move between two renames in one clock tick);
    // only new packs are opened.
    const size_t before = index->packs.size();
    scan(map, *index);
    return index->packs.size() > before;
}

void TileStore::writeNow(const Digest128& map, std::span<const uint64_t> keys,
                         std::span<const unsigned char* const> tiles, size_t tileBytes) {
    if (readOnly_.load(std::memory_order_relaxed) || keys.empty()) return;
    const size_t n = keys.size();
    std::vector<TileHeader> headers(n);
    std::vector<IndexEntry> entries(n);
    uint64_t offset = 0;
    for (size_t i = 0; i < n; ++i) {
        TileHeader& h = headers[i];
        std::memcpy(h.magic, kTileMagic, sizeof kTileMagic);
        h.mapHigh = map.high;
        h.mapLow = map.low;
        h.key = keys[i];
        h.payloadBytes = tileBytes;
        h.checksum = checksum64(tiles[i], tileBytes);
        entries[i] = {keys[i], offset};
        offset += sizeof(TileHeader) + tileBytes;
    }
    const PackFooter footer = footerFor(entries, offset);
    std::vector<std::span<const unsigned char>> pieces;
    for (size_t i = 0; i < n; ++i) {
        pieces.push_back(bytesOf(&headers[i], sizeof(TileHeader)));
        pieces.push_back(bytesOf(tiles[i], tileBytes));
    }
    pieces.push_back(bytesOf(entries.data(), n * sizeof(IndexEntry)));
    pieces.push_back(bytesOf(&footer, sizeof footer));

    const fs::path folder = mapFolder(map);
    const fs::path path = folder / (uniqueName() + ".pack");
    bool ok = writeAtomically(path, pieces);
    if (!ok) {
        // The map's folder may have been removed by a clean-up in another process.
        std::error_code ec;
        fs::create_directories(folder, ec);
        ok = !ec && writeAtomically(path, pieces);
    }
    if (!ok) {
        counters_.writeFailures.fetch_add(1, std::memory_order_relaxed);
        readOnly_.store(true);
        warnOnce("cannot write " + path.string() + ": " + std::strerror(errno));
        return;
    }
    counters_.written.fetch_add(n, std::memory_order_relaxed);
    {
        std::lock_guard<std::mutex> lock(mutex_);
        written_.insert(map.hex());
    }
    // Readers in this process find the pack at once.
    std::shared_ptr<MapIndex> index;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        const auto it = indices_.find(map.hex());
        if (it != indices_.end()) index = it->second;
    }
    if (!index) return;
    std::unique_lock<std::shared_mutex> lock(index->mutex);
    const std::string name = path.filename().string();
    if (index->packs.count(name)) return;
    auto p = std::make_unique<Pack>();
    p->path = path;
    std::error_code ec;
    p->written = fs::last_write_time(path, ec);
    index->add(p.get(), entries);
    index->packs.emplace(name, std::move(p));
}

bool TileStore::readRecord(const Digest128& key, std::vector<unsigned char>& out) {
    const fs::path path = root_ / kRecordsFolder / (key.hex() + ".rep");
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return false;
    struct stat st {};
    TileHeader header{};
    bool ok = ::fstat(fd, &st) == 0 && static_cast<uint64_t>(st.st_size) >= sizeof header &&
              readAt(fd, &header, sizeof header, 0) &&
              headerNames(header, key, 0) &&  // a record's key field is 0 (writeRecord)
              header.payloadBytes == static_cast<uint64_t>(st.st_size) - sizeof header;
    if (ok) {
        out.resize(header.payloadBytes);
        ok = readAt(fd, out.data(), out.size(), sizeof header) &&
             checksum64(out.data(), out.size()) == header.checksum;
    }
    ::close(fd);
    if (!ok) {
        counters_.damaged.fetch_add(1, std::memory_order_relaxed);
        ::unlink(path.c_str());
        return false;
    }
    std::error_code ec;
    fs::last_write_time(path, fs::file_time_type::clock::now(), ec);  // used now
    counters_.recordsRead.fetch_add(1, std::memory_order_relaxed);
    return true;
}

void TileStore::writeRecord(const Digest128& key, std::span<const unsigned char> bytes) {
    if (readOnly_.load(std::memory_order_relaxed)) return;
    TileHeader header{};
    std::memcpy(header.magic, kTileMagic, sizeof kTileMagic);
    header.mapHigh = key.high;
    header.mapLow = key.low;
    header.key = 0;
    header.payloadBytes = bytes.size();
    header.checksum = checksum64(bytes.data(), bytes.size());
    const std::span<const unsigned char> pieces[2] = {bytesOf(&header, sizeof header), bytes};
    const fs::path folder = root_ / kRecordsFolder;
    std::error_code ec;
    fs::create_directories(folder, ec);
    if (writeAtomically(folder / (key.hex() + ".rep"), pieces)) {
        counters_.recordsWritten.fetch_add(1, std::memory_order_relaxed);
        return;
    }
    counters_.writeFailures.fetch_add(1, std::memory_order_relaxed);
    readOnly_.store(true);
    warnOnce("cannot write in " + folder.string() + ": " + std::strerror(errno));
}

void TileStore::useMap(const Digest128& map, const StoredMapInfo& info) {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        if (!used_.insert(map.hex()).second) return;
    }
    const fs::path folder = mapFolder(map);
    std::error_code ec;
    fs::create_directories(folder, ec);
    if (!fs::exists(folder / "map.json", ec)) {
        const nlohmann::json j = {{"object", info.object},         {"shader", info.shader},
                                  {"channels", info.channelNames}, {"charts", info.charts},
                                  {"resolution", info.resolution}, {"tile_size", info.tileSize},
                                  {"border", info.border},         {"half", info.halfPrecision},
                                  {"engine", info.engine}};
        const std::string text = j.dump(1) + "\n";
        const std::span<const unsigned char> piece = bytesOf(text.data(), text.size());
        writeAtomically(folder / "map.json", {&piece, 1});
    }
    // The map's last use, for clean-up by least recent use.
    std::FILE* f = std::fopen((folder / "used").c_str(), "wb");
    if (f) std::fclose(f);
    fs::last_write_time(folder / "used", fs::file_time_type::clock::now(), ec);
}

std::vector<StoredMapSummary> TileStore::maps(bool countPacks) const {
    std::vector<StoredMapSummary> out;
    std::error_code ec;
    for (const fs::directory_entry& folder : fs::directory_iterator(root_ / kTilesFolder, ec)) {
        StoredMapSummary m;
        if (!folder.is_directory(ec) ||
            !Digest128::fromHex(folder.path().filename().string(), m.digest))
            continue;
        if (countPacks)
            for (const fs::directory_entry& f : fs::directory_iterator(folder.path(), ec)) {
                if (f.path().extension() != ".pack") continue;
                const uint64_t size = f.file_size(ec);
                ++m.packs;
                m.bytes += size;
                const int fd = ::open(f.path().c_str(), O_RDONLY | O_CLOEXEC);
                PackFooter footer{};
                if (fd >= 0 && size >= sizeof footer &&
                    readAt(fd, &footer, sizeof footer, size - sizeof footer) &&
                    std::memcmp(footer.magic, kPackMagic, sizeof kPackMagic) == 0)
                    m.tiles += footer.count;
                if (fd >= 0) ::close(fd);
            }
        m.lastUsed = fs::last_write_time(folder.path() / "used", ec);
        if (ec) m.lastUsed = fs::last_write_time(folder.path(), ec);
        // What the map is, if its description reads as one (a damaged one leaves it blank).
        std::ifstream in(folder.path() / "map.json");
        const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
        try {
            if (j.is_object()) {
                m.info.object = j.value("object", "");
                m.info.shader = j.value("shader", "");
                m.info.channelNames = j.value("channels", std::vector<std::string>{});
                m.info.charts = j.value("charts", 0);
                m.info.resolution = j.value("resolution", 0);
                m.info.tileSize = j.value("tile_size", 0);
                m.info.border = j.value("border", 0);
                m.info.halfPrecision = j.value("half", false);
                m.info.engine = j.value("engine", "");
            }
        } catch (const nlohmann::json::exception&) {
            m.info = {};
        }
        out.push_back(std::move(m));
    }
    std::sort(out.begin(), out.end(), [](const StoredMapSummary& a, const StoredMapSummary& b) {
        return a.lastUsed < b.lastUsed;
    });
    return out;
}

namespace {

// What clean-up weighs: a map (its folder) or a record (its file), by last use.
struct StoreEntry {
    fs::path path;
    uint64_t bytes;
    fs::file_time_type lastUsed;
};

std::vector<StoreEntry> records(const fs::path& folder) {
    std::vector<StoreEntry> out;
    std::error_code ec;
    for (const fs::directory_entry& f : fs::directory_iterator(folder, ec))
        if (f.path().extension() == ".rep")
            out.push_back({f.path(), f.file_size(ec), f.last_write_time(ec)});
    return out;
}

}  // namespace

uint64_t TileStore::bytes() const {
    uint64_t total = 0;
    for (const StoredMapSummary& m : maps()) total += m.bytes;
    for (const StoreEntry& r : records(root_ / kRecordsFolder)) total += r.bytes;
    return total;
}

uint64_t TileStore::gc(uint64_t budgetBytes) {
    std::vector<StoreEntry> all = records(root_ / kRecordsFolder);
    for (const StoredMapSummary& m : maps())
        all.push_back({mapFolder(m.digest), m.bytes, m.lastUsed});
    std::sort(all.begin(), all.end(),
              [](const StoreEntry& a, const StoreEntry& b) { return a.lastUsed < b.lastUsed; });
    uint64_t total = 0, removed = 0;
    for (const StoreEntry& e : all) total += e.bytes;
    std::error_code ec;
    const auto stale = fs::file_time_type::clock::now() - std::chrono::hours(1);
    for (const StoreEntry& e : all) {
        if (total > budgetBytes) {
            fs::remove_all(e.path, ec);
            total -= e.bytes;
            removed += e.bytes;
            continue;
        }
        if (!fs::is_directory(e.path, ec)) continue;
        for (const fs::directory_entry& f : fs::directory_iterator(e.path, ec))
            if (f.path().extension() == ".tmp" && f.last_write_time(ec) < stale)
                fs::remove(f.path(), ec);
    }
    for (const fs::directory_entry& f : fs::directory_iterator(root_ / kRecordsFolder, ec))
        if (f.path().extension() == ".tmp" && f.last_write_time(ec) < stale)
            fs::remove(f.path(), ec);
    return removed;
}

}  // namespace mpshade
