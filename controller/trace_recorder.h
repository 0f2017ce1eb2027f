// trace_recorder.h -- keeps the spans the phases report (phases/phase_trace.h) and writes
// them in the Chrome trace-event format (the JSON object form, "X" complete events, times
// in microseconds), which Perfetto and chrome://tracing open.
//
// Two views of the same spans: process 1, "phases", has a track per phase kind (frames,
// static phase, dynamic phase, resolve, single-phase frames) with the phase-level spans,
// so a frame's phases line up under it; process 2, "threads", has a track
// per thread that reported anything (the rendering thread first, then worker threads in
// the order they first reported), with every span it ran, so idle workers show as gaps.
#pragma once

#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "phases/phase_trace.h"

namespace mpshade {

class TraceRecorder final : public PhaseTrace {
  public:
    struct Span {
        const char* name;
        PhaseKind kind;
        SpanLevel level;
        double beginUs, endUs;  // since the recorder was made
        int64_t object, frame;
        int thread;  // 0: the thread that made the recorder; then in order of first report
    };

    // The thread constructing the recorder is the rendering thread (thread 0).
    // objectNames: names for the spans' object indices in the written trace.
    explicit TraceRecorder(std::vector<std::string> objectNames = {});

    void span(const char* name, PhaseKind kind, SpanLevel level, Clock::time_point begin,
              Clock::time_point end, int64_t object, int64_t frame) override;

    // The spans so far, in the order they ended.
    std::vector<Span> spans() const;
    int threads() const;

    // The trace as JSON text: {"traceEvents": [...], "displayTimeUnit": "ms"}.
    std::string chromeTraceJson() const;

  private:
    int threadIndex(std::thread::id id);  // with mutex_ held

    Clock::time_point origin_;
    std::vector<std::string> objectNames_;
    mutable std::mutex mutex_;
    std::vector<Span> spans_;
    std::vector<std::thread::id> threadIds_;
};

// The track name of a phase kind in the "phases" process.
const char* phaseTrackName(PhaseKind kind);

}  // namespace mpshade
