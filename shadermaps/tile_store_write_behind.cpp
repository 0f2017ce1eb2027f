// TileStore's write-behind (tile_store.h): packs written by a thread of the store's own.
#include <algorithm>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <thread>

#include "shadermaps/tile_store.h"

namespace mpshade {

struct TileStore::WriteBehind {
    struct Job {
        Digest128 map;
        std::vector<uint64_t> keys;
        std::vector<unsigned char> bytes;  // the tiles' storage, one after another
        size_t tileBytes = 0;
    };
    std::mutex mutex;
    std::condition_variable wake, drained;
    std::deque<Job> jobs;
    bool writing = false, stopping = false;
    std::thread worker;

    void run(TileStore& store) {
        std::unique_lock<std::mutex> lock(mutex);
        for (;;) {
            wake.wait(lock, [&] { return stopping || !jobs.empty(); });
            if (jobs.empty()) return;  // stopping, nothing left
            Job job = std::move(jobs.front());
            jobs.pop_front();
            writing = true;
            lock.unlock();
            std::vector<const unsigned char*> tiles(job.keys.size());
            for (size_t i = 0; i < tiles.size(); ++i) tiles[i] = &job.bytes[i * job.tileBytes];
            store.writeNow(job.map, job.keys, tiles, job.tileBytes);
            lock.lock();
            writing = false;
            if (jobs.empty()) drained.notify_all();
        }
    }
};

TileStore::~TileStore() {
    setWriteBehind(false);
}

void TileStore::setWriteBehind(bool on) {
    if (on == (writeBehind_ != nullptr)) return;
    if (on) {
        writeBehind_ = std::make_shared<WriteBehind>();
        writeBehind_->worker = std::thread([this] { writeBehind_->run(*this); });
        return;
    }
    {
        std::lock_guard<std::mutex> lock(writeBehind_->mutex);
        writeBehind_->stopping = true;
    }
    writeBehind_->wake.notify_all();
    writeBehind_->worker.join();  // after the last job queued
    writeBehind_.reset();
}

void TileStore::flush() {
    if (!writeBehind_) return;
    std::unique_lock<std::mutex> lock(writeBehind_->mutex);
    writeBehind_->drained.wait(
        lock, [&] { return writeBehind_->jobs.empty() && !writeBehind_->writing; });
}

void TileStore::write(const Digest128& map, std::span<const uint64_t> keys,
                      std::span<const unsigned char* const> tiles, size_t tileBytes) {
    if (!writeBehind_) {
        writeNow(map, keys, tiles, tileBytes);
        return;
    }
    if (readOnly_.load(std::memory_order_relaxed) || keys.empty()) return;
    WriteBehind::Job job{map, {keys.begin(), keys.end()}, {}, tileBytes};
    job.bytes.resize(keys.size() * tileBytes);
    for (size_t i = 0; i < keys.size(); ++i)
        std::copy_n(tiles[i], tileBytes,
                    job.bytes.begin() + static_cast<std::ptrdiff_t>(i * tileBytes));
    {
        std::lock_guard<std::mutex> lock(writeBehind_->mutex);
        writeBehind_->jobs.push_back(std::move(job));
    }
    writeBehind_->wake.notify_one();
}

}  // namespace mpshade
