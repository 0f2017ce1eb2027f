#include "shadermaps/tile_pool.h"

#include <algorithm>
#include <cstring>
#include <new>

#include <sys/mman.h>

#include "geometry/error.h"

namespace mpshade {

TilePool::TilePool(size_t tileBytes)
    : tileBytes_(tileBytes),
      blocks_(std::make_unique<std::unique_ptr<Block>[]>(kMaxTiles / kTilesPerBlock)) {}

namespace {
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kAddressSanitized = true;
#else
constexpr bool kAddressSanitized = false;
#endif
#else
constexpr bool kAddressSanitized = false;
#endif
constexpr size_t kHugePage = size_t{2} << 20;
constexpr size_t kChunkBytes = 4 * kHugePage;
}  // namespace

TilePool::Chunk::~Chunk() {
    if (base && !owned) ::munmap(base, bytes);
}

// Under mutex_. Blocks are carved 64-byte aligned from the newest chunk; a block larger
// than a chunk gets one of its own.
unsigned char* TilePool::blockStorage(size_t bytes) {
    if (kAddressSanitized) {
        // Under AddressSanitizer each block is an allocation of its own, so a read past one
        // is caught (mapped chunks carry no red zones).
        auto chunk = std::make_unique<Chunk>();
        chunk->owned = std::make_unique_for_overwrite<unsigned char[]>(bytes);
        chunk->bytes = chunk->used = bytes;
        unsigned char* at = chunk->owned.get();
        chunks_.push_back(std::move(chunk));
        return at;
    }
    const size_t need = (bytes + 63) & ~size_t{63};
    if (chunks_.empty() || chunks_.back()->used + need > chunks_.back()->bytes) {
        auto chunk = std::make_unique<Chunk>();
        chunk->bytes = std::max(kChunkBytes, (need + kHugePage - 1) / kHugePage * kHugePage);
        // One huge page more than needed, to start the chunk on a huge-page boundary.
        const size_t mapped = chunk->bytes + kHugePage;
        void* p =
            ::mmap(nullptr, mapped, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (p == MAP_FAILED) throw std::bad_alloc();
        auto* raw = static_cast<unsigned char*>(p);
        auto* aligned = reinterpret_cast<unsigned char*>(
            (reinterpret_cast<uintptr_t>(raw) + kHugePage - 1) & ~(kHugePage - 1));
        if (aligned > raw) ::munmap(raw, static_cast<size_t>(aligned - raw));
        const size_t tail = mapped - static_cast<size_t>(aligned - raw) - chunk->bytes;
        if (tail > 0) ::munmap(aligned + chunk->bytes, tail);
        ::madvise(aligned, chunk->bytes, MADV_HUGEPAGE);  // advice: a kernel may ignore it
        chunk->base = aligned;
        chunks_.push_back(std::move(chunk));
    }
    Chunk& c = *chunks_.back();
    unsigned char* at = c.base + c.used;
    c.used += need;
    return at;
}

int TilePool::allocate(ShaderMap* owner, uint64_t key, bool pinned, uint32_t stamp) {
    std::lock_guard<std::mutex> lock(mutex_);
    int slot;
    if (!free_.empty()) {
        slot = free_.back();
        free_.pop_back();
    } else {
        slot = static_cast<int>(owner_.size());
        MPSHADE_CHECK(owner_.size() < kMaxTiles);
        const size_t blocks = blockCount_.load(std::memory_order_relaxed);
        if (owner_.size() == blocks * kTilesPerBlock) {
            auto block = std::make_unique<Block>();
            // Not zeroed: a fill writes every texel a probe can read (a reused slot holds an
            // old tile's texels anyway), and zeroing took 6.7% of the grazing floor's frames
            // under perf (a pass over memory the fill then writes). The slack, read only by
            // whole-vector loads whose extra lanes are dropped, is zeroed.
            const size_t bytes = kTilesPerBlock * tileBytes_;
            block->data = blockStorage(bytes + kSlackBytes);
            std::memset(block->data + bytes, 0, kSlackBytes);
            for (std::atomic<uint32_t>& use : block->lastUse)
                use.store(0, std::memory_order_relaxed);
            blocks_[blocks] = std::move(block);
            blockCount_.store(blocks + 1, std::memory_order_relaxed);
        }
        owner_.push_back(nullptr);
        key_.push_back(0);
        pinned_.push_back(0);
    }
    const size_t s = static_cast<size_t>(slot);
    owner_[s] = owner;
    key_[s] = key;
    pinned_[s] = pinned ? 1 : 0;
    useOf(slot).store(stamp, std::memory_order_relaxed);
    held_.fetch_add(1, std::memory_order_relaxed);
    if (pinned) pinnedHeld_.fetch_add(1, std::memory_order_relaxed);
    return slot;
}

void TilePool::release(int slot) {
    free_.push_back(slot);
    held_.fetch_sub(1, std::memory_order_relaxed);
    if (pinned_[static_cast<size_t>(slot)]) pinnedHeld_.fetch_sub(1, std::memory_order_relaxed);
}

void TilePool::free(int slot) {
    std::lock_guard<std::mutex> lock(mutex_);
    const size_t s = static_cast<size_t>(slot);
    MPSHADE_CHECK(s < owner_.size() && owner_[s] != nullptr);
    owner_[s] = nullptr;
    release(slot);
}

void TilePool::retire(int slot) {
    std::lock_guard<std::mutex> lock(mutex_);
    const size_t s = static_cast<size_t>(slot);
    MPSHADE_CHECK(s < owner_.size() && owner_[s] != nullptr);
    owner_[s] = nullptr;
    retired_.push_back(slot);
}

void TilePool::reclaim() {
    std::lock_guard<std::mutex> lock(mutex_);
    for (int slot : retired_) release(slot);
    retired_.clear();
}

void TilePool::evictable(uint32_t before, std::vector<Held>& out) const {
    std::lock_guard<std::mutex> lock(mutex_);
    for (size_t s = 0; s < owner_.size(); ++s) {
        if (!owner_[s] || pinned_[s]) continue;
        const uint32_t use = lastUse(static_cast<int>(s));
        if (use < before) out.push_back({use, static_cast<int>(s), owner_[s], key_[s]});
    }
}

std::shared_ptr<TilePool> TilePools::forTileBytes(size_t tileBytes) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& pool : pools_)
        if (pool->tileBytes() == tileBytes) return pool;
    pools_.push_back(std::make_shared<TilePool>(tileBytes));
    return pools_.back();
}

std::vector<std::shared_ptr<TilePool>> TilePools::all() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return pools_;
}

size_t TilePools::smallestTileBytes() const {
    std::lock_guard<std::mutex> lock(mutex_);
    size_t smallest = 0;
    for (const auto& pool : pools_)
        smallest = smallest ? std::min(smallest, pool->tileBytes()) : pool->tileBytes();
    return smallest;
}

size_t TilePools::bytesHeld() const {
    std::lock_guard<std::mutex> lock(mutex_);
    size_t bytes = 0;
    for (const auto& pool : pools_) bytes += pool->bytesHeld();
    return bytes;
}

}  // namespace mpshade
