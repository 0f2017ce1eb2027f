// stop_signal.h -- when long work (a shader-map fill, the static shader's runs over its
// texels) should stop early: a request from another thread (a frame taking its core back
// from the background filler), or a deadline on the steady clock (a locked-rate frame's fills
// must end within its budget), whichever comes first. A fill checks it before each tile, a
// kernel before its first run of ShaderKernel::kLanes points and after each, and occlusion
// between streams of rays (ShaderMap::fill): stopping costs at most a tile's surface
// evaluation or one stream of rays.
#pragma once

#include <atomic>
#include <chrono>

namespace mpshade {

class StopSignal {
  public:
    using Clock = std::chrono::steady_clock;

    // No deadline: stops only when asked to.
    StopSignal() = default;
    explicit StopSignal(Clock::time_point deadline) : deadline_(deadline) {}
    StopSignal(const StopSignal&) = delete;
    StopSignal& operator=(const StopSignal&) = delete;

    // From any thread.
    void request() { stopped_.store(true, std::memory_order_relaxed); }
    void clear() { stopped_.store(false, std::memory_order_relaxed); }

    // True once asked to, or once the deadline has passed (then without reading the clock
    // again). Safe from several threads at once; reads no clock without a deadline.
    bool stopped() const {
        if (stopped_.load(std::memory_order_relaxed)) return true;
        if (deadline_ == Clock::time_point::max() || Clock::now() <= deadline_) return false;
        stopped_.store(true, std::memory_order_relaxed);
        return true;
    }

  private:
    Clock::time_point deadline_ = Clock::time_point::max();
    mutable std::atomic<bool> stopped_{false};
};

}  // namespace mpshade
