// idle_priority.h -- the controller's worker threads (background_filler.h,
// background_builder.h) run at idle priority, so they take a core only when the frame's own
// work leaves one idle.
#pragma once

#include <sched.h>
#include <sys/resource.h>

namespace mpshade {

// Puts the calling thread at SCHED_IDLE, else (where that is refused) at nice 19.
inline void lowerToIdlePriority() {
    sched_param param{};
    if (sched_setscheduler(0, SCHED_IDLE, &param) != 0) setpriority(PRIO_PROCESS, 0, 19);
}

}  // namespace mpshade
