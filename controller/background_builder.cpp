#include "controller/background_builder.h"

#include "controller/idle_priority.h"

#include <algorithm>
#include <ctime>

#include <tbb/task_arena.h>

namespace mpshade {
namespace {

double threadCpuSeconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace

BackgroundBuilder::BackgroundBuilder(const StaticPhase& phase, bool idlePriority)
    : phase_(phase), idlePriority_(idlePriority), worker_([this] { run(); }) {}

BackgroundBuilder::~BackgroundBuilder() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stop_ = true;
    }
    wake_.notify_all();
    worker_.join();
}

void BackgroundBuilder::submit(RebuildJob job) {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        if (busy_ && current_ == job.object) return;
        for (const RebuiltObject& done : finished_)
            if (done.job.object == job.object) return;
        const auto queued = std::find_if(queue_.begin(), queue_.end(), [&](const RebuildJob& q) {
            return q.object == job.object;
        });
        if (queued != queue_.end())
            *queued = std::move(job);
        else
            queue_.push_back(std::move(job));
    }
    wake_.notify_all();
}

bool BackgroundBuilder::pending(size_t object) const {
    std::lock_guard<std::mutex> lock(mutex_);
    if (busy_ && current_ == object) return true;
    for (const RebuildJob& q : queue_)
        if (q.object == object) return true;
    for (const RebuiltObject& done : finished_)
        if (done.job.object == object) return true;
    return false;
}

std::vector<RebuiltObject> BackgroundBuilder::takeFinished() {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<RebuiltObject> out;
    out.swap(finished_);
    return out;
}

void BackgroundBuilder::discard(std::unique_ptr<ObjectRepresentation> representation) {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        discarded_.push_back(std::move(representation));
    }
    wake_.notify_all();
}

void BackgroundBuilder::cancel() {
    std::unique_lock<std::mutex> lock(mutex_);
    queue_.clear();
    dropCurrent_ = busy_;
    idle_.wait(lock, [&] { return !busy_; });
    dropCurrent_ = false;
    finished_.clear();
    discarded_.clear();
}

void BackgroundBuilder::waitIdle() {
    std::unique_lock<std::mutex> lock(mutex_);
    idle_.wait(lock, [&] { return !busy_ && queue_.empty(); });
}

void BackgroundBuilder::run() {
    if (idlePriority_) lowerToIdlePriority();
    // The builds run on this thread alone: none of the frame's workers join them.
    tbb::task_arena arena(1);
    std::vector<std::unique_ptr<ObjectRepresentation>> discarded;
    for (;;) {
        RebuildJob job;
        {
            std::unique_lock<std::mutex> lock(mutex_);
            wake_.wait(lock, [&] { return stop_ || !queue_.empty() || !discarded_.empty(); });
            if (stop_) return;
            if (!discarded_.empty()) {
                // Freed outside the lock; busy_ keeps cancel() waiting until it is done.
                discarded.swap(discarded_);
                busy_ = true;
                current_ = ~size_t{0};
                lock.unlock();
                discarded.clear();
                lock.lock();
                busy_ = false;
                idle_.notify_all();
                continue;
            }
            job = std::move(queue_.front());
            queue_.pop_front();
            busy_ = true;
            current_ = job.object;
        }
        RebuiltObject done;
        const double cpu = threadCpuSeconds();
        arena.execute([&] {
            done.representation = phase_.build(job.object, job.kind, job.state, job.camera,
                                               job.ownUniforms(), job.previous, done.costs);
        });
        done.costs.seconds = threadCpuSeconds() - cpu;
        done.job = std::move(job);
        {
            std::lock_guard<std::mutex> lock(mutex_);
            // Dropped here, while cancel() waits: a lent map it may hold the last share of
            // is then freed with the controller held, not beside it.
            if (dropCurrent_)
                done = RebuiltObject{};
            else
                finished_.push_back(std::move(done));
            busy_ = false;
        }
        idle_.notify_all();
    }
}

}  // namespace mpshade
