// work_deadline.h -- a deadline shared by the parallel loops of one piece of work (the
// rasterizer's chunks and tiles, the dynamic phase's bands): once the clock has passed
// it, every later check says so without reading the clock again, so the loop's remaining
// items return at once. Without a deadline (time_point::max()) a check reads no clock.
#pragma once

#include <atomic>
#include <chrono>

namespace mpshade {

class WorkDeadline {
  public:
    using Clock = std::chrono::steady_clock;

    explicit WorkDeadline(Clock::time_point at) : at_(at), timed_(at != Clock::time_point::max()) {}

    // True once the deadline has passed; safe from several threads at once.
    bool passed() {
        if (!timed_) return false;
        if (missed_.load(std::memory_order_relaxed)) return true;
        if (Clock::now() <= at_) return false;
        missed_.store(true, std::memory_order_relaxed);
        return true;
    }
    // Whether some check found it passed (work was skipped).
    bool missed() const { return missed_.load(std::memory_order_relaxed); }

  private:
    Clock::time_point at_;
    bool timed_;
    std::atomic<bool> missed_{false};
};

}  // namespace mpshade
