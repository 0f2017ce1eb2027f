// interrupt_watch.h -- Ctrl-C during a render: the first SIGINT asks the render to stop
// after the frame under way (every finished frame and stats.json stay valid); a second one
// stops the process at once (the files already written stay valid too: output_files.h).
#pragma once

namespace mpshade {

// While one is alive, SIGINT is watched; the previous handler comes back when it dies.
class InterruptWatch {
  public:
    InterruptWatch();
    ~InterruptWatch();
    InterruptWatch(const InterruptWatch&) = delete;
    InterruptWatch& operator=(const InterruptWatch&) = delete;
};

// Whether SIGINT arrived since the watch began.
bool interrupted();

}  // namespace mpshade
