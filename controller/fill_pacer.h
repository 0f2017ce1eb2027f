// fill_pacer.h -- sizes the chunks of shader-map tile fills that must end by a deadline
// (a frame's time left: MultiphaseRenderer's fills within the budget and its prefetching).
// A chunk takes half the time left at the most a tile has cost lately: tiles built from
// resident children cost a fifth of those evaluated whole, so chunks sized for the average
// overran. The cost is measured on chunks every thread fills, so a chunk smaller than the
// threads (slower per tile) is not started.
#pragma once

#include <algorithm>
#include <cstddef>

#include "phases/worker_threads.h"

namespace mpshade {

class FillPacer {
  public:
    // lastWorst: what remembered() of the previous pacer gave (0: nothing measured yet).
    explicit FillPacer(double lastWorst)
        : perTile_(lastWorst), threads_(static_cast<size_t>(workerThreads())) {}

    // Tiles the next chunk may take with `left` seconds to go; 0: stop here.
    size_t chunk(double left) const {
        const size_t n = perTile_ > 0.0
                             ? static_cast<size_t>(std::clamp(0.5 * left / perTile_, 0.0, 4096.0))
                             : 2;
        return left <= 0.0 || n < (perTile_ > 0.0 ? threads_ : 1) ? 0 : n;
    }
    // A chunk of `tiles` took `seconds`.
    void filled(double seconds, size_t tiles) {
        perTile_ = std::max(perTile_, seconds / static_cast<double>(tiles));
    }
    // For the next pacer: nine tenths of the worst seen, so it is forgotten slowly.
    double remembered() const { return 0.9 * perTile_; }

  private:
    double perTile_;  // seconds a tile, the most a chunk took
    size_t threads_;
};

}  // namespace mpshade
