#include "app/interrupt_watch.h"

#include <csignal>

#include <unistd.h>

namespace mpshade {
namespace {

volatile std::sig_atomic_t gInterrupted = 0;
struct sigaction gPrevious;

extern "C" void onInterrupt(int) {
    gInterrupted = 1;
    // Only async-signal-safe calls here: write(2) and restoring the default action, so
    // the next Ctrl-C ends the process.
    static const char kMessage[] =
        "\nmpshade: stopping after this frame (Ctrl-C again to stop at once)\n";
    (void)!::write(STDERR_FILENO, kMessage, sizeof kMessage - 1);
    std::signal(SIGINT, SIG_DFL);
}

}  // namespace

InterruptWatch::InterruptWatch() {
    gInterrupted = 0;
    struct sigaction action {};
    action.sa_handler = onInterrupt;
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, &gPrevious);
    // A process started with SIGINT ignored (a background job of a script, nohup) keeps
    // ignoring it.
    if (gPrevious.sa_handler == SIG_IGN) sigaction(SIGINT, &gPrevious, nullptr);
}

InterruptWatch::~InterruptWatch() {
    sigaction(SIGINT, &gPrevious, nullptr);
}

bool interrupted() {
    return gInterrupted != 0;
}

}  // namespace mpshade
