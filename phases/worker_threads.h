// worker_threads.h -- how many threads a parallel loop started here may use: the task
// arena's concurrency, capped by a process-wide tbb::global_control limit (`--threads N`,
// MPSHADE_BENCH_THREADS), which does not change the arena's own figure.
#pragma once

#include <algorithm>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

namespace mpshade {

inline int workerThreads() {
    const auto limit =
        tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
    return std::max(1, std::min(tbb::this_task_arena::max_concurrency(), static_cast<int>(limit)));
}

}  // namespace mpshade
