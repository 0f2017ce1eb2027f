// background_filler.h -- fills shader-map tiles on a worker thread beside the frames: the
// tiles a locked-rate frame found missing and had no time left to fill are queued here, and the
// worker fills them while the controller does other things -- the frame's image being
// written, a prediction's probes of the same maps (controller/tile_prefetch.cpp), the next
// frame's dynamic phase if the controller lets it (MultiphaseOptions::
// backgroundDuringFrames). Each tile appears to probes once whole; until then they read the
// finest coarser level resident. Patent col. 10-11: the controller schedules static work
// apart from the frames that need it.
//
// The worker runs at idle priority (SCHED_IDLE, else nice 19) on one thread, so it takes a
// core only when the frame's own work leaves one idle. It keeps the tiles under the cache's
// budget: when a tile would not fit it drops tiles no probe used in the last two frames,
// oldest first, while probes may run -- through ShaderMap::retire, so a probe that found
// such a tile a moment before still reads whole storage (its slot is reused only after the
// pools' reclaim, which the controller runs between frames, with the worker paused) -- and
// then waits for that reclaim.
//
// Threads: every method is called from one controlling thread. Between pause() and
// resume() the worker touches nothing: the controller may then rebuild or destroy maps,
// fill, evict and reclaim.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "controller/tile_cache.h"
#include "shadermaps/shader_map.h"

namespace mpshade {

struct BackgroundJob {
    uint32_t object = 0;
    std::shared_ptr<ShaderMap> map;  // kept alive while queued
    TileKey key;
};

struct BackgroundTotals {
    uint64_t tilesFilled = 0, tilesEvicted = 0;
    double seconds = 0.0;  // the worker's wall time filling and evicting
};

class BackgroundFiller {
  public:
    // pools: the renderer's (not owned; must outlive the filler). budgetBytes: the cache's.
    // idlePriority false: the worker runs at normal priority (a caller that waits on it
    // while other processes load the machine, as tests under `ctest -j` do).
    BackgroundFiller(const TilePools& pools, size_t budgetBytes, bool idlePriority = true);
    ~BackgroundFiller();
    BackgroundFiller(const BackgroundFiller&) = delete;
    BackgroundFiller& operator=(const BackgroundFiller&) = delete;

    // Replaces the queue, filled in order. Only while paused.
    void submit(std::vector<BackgroundJob> jobs);
    // Keeps only the queued jobs `keep` accepts. Only while paused.
    void retain(const std::function<bool(const BackgroundJob&)>& keep);
    // Returns once the worker is between tiles, and holds it there until resume().
    void pause();
    // Lets the worker go on. `stamp`: the use stamp of the frame about to render; tiles used
    // at it or the one before are never dropped to make room.
    void resume(uint32_t stamp);
    // Since construction. Read while paused for exact figures.
    BackgroundTotals totals() const;
    // Jobs queued and not yet done (a batch being filled counts).
    size_t queued() const;
    // Whether the worker can do nothing more before the next frame: paused, or idle with
    // its queue done or the cache full of tiles it may not drop yet.
    bool settled() const;

    // Holds a filler (null: none) paused for a scope, so the holder's fills and evictions
    // are the cache's only ones; resumes it at `stamp` on leaving. `seconds`: the wait for
    // the worker's tile under way.
    class Hold {
      public:
        Hold(BackgroundFiller* filler, uint32_t stamp);
        ~Hold() {
            if (filler_) filler_->resume(stamp_);
        }
        Hold(const Hold&) = delete;
        Hold& operator=(const Hold&) = delete;
        double seconds() const { return seconds_; }

      private:
        BackgroundFiller* filler_;
        uint32_t stamp_;
        double seconds_ = 0.0;
    };

  private:
    void run();
    // Retires the tiles unused longest (last used before stamp - 1) until `wanted` bytes
    // are on their way to being free.
    void makeRoom(size_t wanted, uint32_t stamp, uint64_t& evicted);

    const TilePools& pools_;
    size_t budget_;
    mutable std::mutex mutex_;
    std::condition_variable wake_, idle_;
    std::vector<BackgroundJob> jobs_;
    size_t next_ = 0;
    bool idlePriority_;
    bool paused_ = true, busy_ = false, stop_ = false;
    // Set while pause() waits: the fill in progress drops its level and returns, so a
    // frame waits for at most a run of the static shader, not a whole tile.
    StopSignal abandon_;
    bool waitForReclaim_ = false;  // the cache is full: nothing more until the next frame
    uint32_t stamp_ = 0;
    BackgroundTotals totals_;
    std::vector<TilePool::Held> candidates_;  // the worker's own
    std::thread worker_;
};

}  // namespace mpshade
