// phase_trace.h -- where the phases report what they spend their time on, for cost
// profiling (`mpshade profile`; controller/trace_recorder.h writes it as a Chrome trace).
//
// A span is a stretch of wall-clock time on the thread that reports it: a whole phase of a
// frame on the calling thread, or one task of a parallel loop (an object's static phase, a
// band's shading) on whichever worker ran it. Spans are reported per task, never per sample:
// a frame reports a few hundred. With no sink (the default) nothing is measured.
#pragma once

#include <chrono>
#include <cstdint>

namespace mpshade {

// Whether a span is a phase of a frame, reported by the thread rendering it, or one task of a
// parallel loop, reported by whichever thread ran it.
enum class SpanLevel : uint8_t { Phase, Task };

// What a span is part of; a profile shows each on a track of its own.
enum class PhaseKind : uint8_t {
    Frame,      // a whole frame
    Static,     // the static phase: dicing, tile fills
    Dynamic,    // the dynamic phase: warp, rasterize, shade
    Resolve,    // pixel reconstruction
    Reference,  // a frame rendered single-phase
};

// Seconds of the steady clock since `start`: how every phase times itself.
inline double secondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

class PhaseTrace {
  public:
    using Clock = std::chrono::steady_clock;
    virtual ~PhaseTrace() = default;
    // [begin, end) on the calling thread. `name` must outlive the sink (a string literal);
    // object: the scene object it worked for, or -1; frame: the frame, or -1.
    virtual void span(const char* name, PhaseKind kind, SpanLevel level, Clock::time_point begin,
                      Clock::time_point end, int64_t object, int64_t frame) = 0;
};

// Reports the span from its construction to its destruction; does nothing without a sink.
class ScopedSpan {
  public:
    ScopedSpan(PhaseTrace* trace, const char* name, PhaseKind kind, SpanLevel level,
               int64_t object = -1, int64_t frame = -1)
        : trace_(trace), name_(name), kind_(kind), level_(level), object_(object), frame_(frame) {
        if (trace_) begin_ = PhaseTrace::Clock::now();
    }
    ~ScopedSpan() {
        if (trace_)
            trace_->span(name_, kind_, level_, begin_, PhaseTrace::Clock::now(), object_, frame_);
    }
    ScopedSpan(const ScopedSpan&) = delete;
    ScopedSpan& operator=(const ScopedSpan&) = delete;

  private:
    PhaseTrace* trace_;
    const char* name_;
    PhaseKind kind_;
    SpanLevel level_;
    int64_t object_, frame_;
    PhaseTrace::Clock::time_point begin_{};
};

}  // namespace mpshade
