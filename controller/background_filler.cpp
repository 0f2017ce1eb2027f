#include "controller/background_filler.h"

#include "controller/idle_priority.h"

#include <chrono>

#include <tbb/task_arena.h>

namespace mpshade {
namespace {

// Tiles taken at once: pause() waits for at most this many (the dearest tiles seen cost
// about 1 ms each; two a batch had held a frame up to 5 ms).
constexpr size_t kBatch = 1;

}  // namespace

BackgroundFiller::BackgroundFiller(const TilePools& pools, size_t budgetBytes, bool idlePriority)
    : pools_(pools),
      budget_(budgetBytes),
      idlePriority_(idlePriority),
      worker_([this] { run(); }) {}

BackgroundFiller::~BackgroundFiller() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stop_ = true;
    }
    wake_.notify_all();
    worker_.join();
}

BackgroundFiller::Hold::Hold(BackgroundFiller* filler, uint32_t stamp)
    : filler_(filler), stamp_(stamp) {
    if (!filler_) return;
    const auto start = std::chrono::steady_clock::now();
    filler_->pause();
    seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void BackgroundFiller::submit(std::vector<BackgroundJob> jobs) {
    std::lock_guard<std::mutex> lock(mutex_);
    jobs_ = std::move(jobs);
    next_ = 0;
}

void BackgroundFiller::retain(const std::function<bool(const BackgroundJob&)>& keep) {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<BackgroundJob> kept;
    for (size_t k = next_; k < jobs_.size(); ++k)
        if (keep(jobs_[k])) kept.push_back(std::move(jobs_[k]));
    jobs_ = std::move(kept);
    next_ = 0;
}

void BackgroundFiller::pause() {
    std::unique_lock<std::mutex> lock(mutex_);
    paused_ = true;
    abandon_.request();
    idle_.wait(lock, [&] { return !busy_; });
    abandon_.clear();
}

void BackgroundFiller::resume(uint32_t stamp) {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        paused_ = false;
        if (stamp != stamp_) waitForReclaim_ = false;  // a new frame: the pools reclaimed
        stamp_ = stamp;
    }
    wake_.notify_all();
}

BackgroundTotals BackgroundFiller::totals() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return totals_;
}

size_t BackgroundFiller::queued() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return jobs_.size() - next_ + (busy_ ? 1 : 0);
}

bool BackgroundFiller::settled() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return paused_ || (!busy_ && (next_ >= jobs_.size() || waitForReclaim_));
}

void BackgroundFiller::makeRoom(size_t wanted, uint32_t stamp, uint64_t& evicted) {
    const size_t count = oldestTiles(pools_, stamp > 0 ? stamp - 1 : 0, wanted, candidates_);
    // Retired tiles hold their storage until the controller's next reclaim, so the room
    // made here is for the frames after it.
    size_t freed = 0;
    for (size_t i = 0; i < count && freed < wanted; ++i) {
        const TilePool::Held& h = candidates_[i];
        h.owner->retire(h.key);
        freed += h.owner->tileBytes();
        ++evicted;
    }
}

void BackgroundFiller::run() {
    if (idlePriority_) lowerToIdlePriority();
    // The worker's fills run on this thread alone: none of the frame's workers join them.
    tbb::task_arena arena(1);
    std::vector<TileKey> keys;
    for (;;) {
        std::shared_ptr<ShaderMap> map;
        uint32_t stamp = 0;
        {
            std::unique_lock<std::mutex> lock(mutex_);
            wake_.wait(lock, [&] {
                return stop_ || (!paused_ && !waitForReclaim_ && next_ < jobs_.size());
            });
            if (stop_) return;
            busy_ = true;
            map = jobs_[next_].map;
            stamp = stamp_;
            keys.clear();
            while (next_ < jobs_.size() && keys.size() < kBatch && jobs_[next_].map == map)
                keys.push_back(jobs_[next_++].key);
        }
        const auto start = std::chrono::steady_clock::now();
        uint64_t evicted = 0, filled = 0;
        std::vector<TileKey> missing;
        for (const TileKey& k : keys)
            if (!map->resident(k)) missing.push_back(k);
        const bool room =
            missing.empty() || pools_.bytesHeld() + missing.size() * map->tileBytes() <= budget_;
        if (!room) {
            // Room for what is queued (an eighth of the budget at most), ready once the
            // controller reclaims; this batch waits for it.
            size_t wanted = 0;
            {
                std::lock_guard<std::mutex> lock(mutex_);
                next_ -= keys.size();
                for (size_t k = next_; k < jobs_.size() && wanted < budget_ / 8; ++k)
                    wanted += jobs_[k].map->tileBytes();
            }
            makeRoom(wanted, stamp, evicted);
        }
        if (room && !missing.empty())
            arena.execute([&] { filled = map->fill(missing, &abandon_).tiles; });
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        map.reset();  // here, not after the controller sees the worker idle
        {
            std::lock_guard<std::mutex> lock(mutex_);
            busy_ = false;
            totals_.tilesFilled += filled;
            totals_.tilesEvicted += evicted;
            totals_.seconds += seconds;
            waitForReclaim_ = !room;
        }
        idle_.notify_all();
    }
}

}  // namespace mpshade
