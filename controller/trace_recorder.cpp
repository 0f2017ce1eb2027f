#include "controller/trace_recorder.h"

#include <nlohmann/json.hpp>

namespace mpshade {

const char* phaseTrackName(PhaseKind kind) {
    switch (kind) {
        case PhaseKind::Frame:
            return "frames";
        case PhaseKind::Static:
            return "static phase";
        case PhaseKind::Dynamic:
            return "dynamic phase";
        case PhaseKind::Resolve:
            return "resolve";
        case PhaseKind::Reference:
            return "single-phase frames";
    }
    return "other";
}

TraceRecorder::TraceRecorder(std::vector<std::string> objectNames)
    : origin_(Clock::now()), objectNames_(std::move(objectNames)) {
    threadIds_.push_back(std::this_thread::get_id());
}

int TraceRecorder::threadIndex(std::thread::id id) {
    for (size_t i = 0; i < threadIds_.size(); ++i)
        if (threadIds_[i] == id) return static_cast<int>(i);
    threadIds_.push_back(id);
    return static_cast<int>(threadIds_.size() - 1);
}

void TraceRecorder::span(const char* name, PhaseKind kind, SpanLevel level, Clock::time_point begin,
                         Clock::time_point end, int64_t object, int64_t frame) {
    const auto us = [&](Clock::time_point t) {
        return std::chrono::duration<double, std::micro>(t - origin_).count();
    };
    const std::thread::id id = std::this_thread::get_id();
    std::lock_guard<std::mutex> lock(mutex_);
    spans_.push_back({name, kind, level, us(begin), us(end), object, frame, threadIndex(id)});
}

std::vector<TraceRecorder::Span> TraceRecorder::spans() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return spans_;
}

int TraceRecorder::threads() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return static_cast<int>(threadIds_.size());
}

std::string TraceRecorder::chromeTraceJson() const {
    std::vector<Span> spans;
    int threadCount;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        spans = spans_;
        threadCount = static_cast<int>(threadIds_.size());
    }
    constexpr int kPhases = 1, kThreads = 2;
    nlohmann::json events = nlohmann::json::array();
    auto metadata = [&](const char* what, int pid, int tid, const std::string& name) {
        events.push_back(
            {{"name", what}, {"ph", "M"}, {"pid", pid}, {"tid", tid}, {"args", {{"name", name}}}});
    };
    metadata("process_name", kPhases, 0, "phases");
    metadata("process_name", kThreads, 0, "threads");
    const PhaseKind kinds[] = {PhaseKind::Frame, PhaseKind::Static, PhaseKind::Dynamic,
                               PhaseKind::Resolve, PhaseKind::Reference};
    for (PhaseKind k : kinds) {
        const int tid = static_cast<int>(k);
        metadata("thread_name", kPhases, tid, phaseTrackName(k));
        events.push_back({{"name", "thread_sort_index"},
                          {"ph", "M"},
                          {"pid", kPhases},
                          {"tid", tid},
                          {"args", {{"sort_index", tid}}}});
    }
    for (int t = 0; t < threadCount; ++t)
        metadata("thread_name", kThreads, t,
                 t == 0 ? std::string("rendering thread") : "worker " + std::to_string(t));
    auto event = [&](const Span& s, int pid, int tid) {
        nlohmann::json args = nlohmann::json::object();
        if (s.frame >= 0) args["frame"] = s.frame;
        if (s.object >= 0) {
            const size_t o = static_cast<size_t>(s.object);
            args["object"] = o < objectNames_.size() ? objectNames_[o] : std::to_string(o);
        }
        nlohmann::json e = {{"name", s.name},
                            {"cat", phaseTrackName(s.kind)},
                            {"ph", "X"},
                            {"ts", s.beginUs},
                            {"dur", std::max(0.0, s.endUs - s.beginUs)},
                            {"pid", pid},
                            {"tid", tid},
                            {"args", args}};
        if (s.object >= 0 && static_cast<size_t>(s.object) < objectNames_.size())
            e["name"] = std::string(s.name) + " " + objectNames_[static_cast<size_t>(s.object)];
        events.push_back(std::move(e));
    };
    for (const Span& s : spans) {
        if (s.level == SpanLevel::Phase) event(s, kPhases, static_cast<int>(s.kind));
        event(s, kThreads, s.thread);
    }
    const nlohmann::json doc = {{"traceEvents", events}, {"displayTimeUnit", "ms"}};
    return doc.dump() + "\n";
}

}  // namespace mpshade
