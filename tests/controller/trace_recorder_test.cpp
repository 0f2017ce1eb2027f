// The Chrome trace: every span on its thread's track, phase-level spans also on their
// phase's track, times in microseconds as reported.
#include <map>
#include <set>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "controller/trace_recorder.h"

namespace mpshade {
namespace {

using Clock = PhaseTrace::Clock;
using std::chrono::microseconds;

TEST(TraceRecorder, SpansLandOnTheirThreadAndPhaseTracksWithTheirTimes) {
    TraceRecorder trace({"floor", "vase"});
    const Clock::time_point t0 = Clock::now();
    trace.span("static phase", PhaseKind::Static, SpanLevel::Phase, t0 + microseconds(1000),
               t0 + microseconds(3500), -1, 7);
    auto worker = [&](int64_t object) {
        trace.span("build", PhaseKind::Static, SpanLevel::Task, t0 + microseconds(1200),
                   t0 + microseconds(2000), object, 7);
    };
    // Both alive at once: a finished thread's id may be given to the next.
    std::thread a(worker, 1), b(worker, 0);
    a.join();
    b.join();
    ASSERT_EQ(trace.threads(), 3);

    const nlohmann::json doc = nlohmann::json::parse(trace.chromeTraceJson());
    ASSERT_TRUE(doc.contains("traceEvents"));
    std::vector<nlohmann::json> complete;
    std::map<std::pair<int, int>, std::string> trackNames;
    for (const nlohmann::json& e : doc["traceEvents"]) {
        if (e["ph"] == "X") complete.push_back(e);
        if (e["ph"] == "M" && e["name"] == "thread_name")
            trackNames[{e["pid"].get<int>(), e["tid"].get<int>()}] = e["args"]["name"];
    }
    // The phase span twice (its phase's track and its thread's), each task once.
    ASSERT_EQ(complete.size(), 4u);
    int onPhaseTrack = 0;
    double staticStart = -1.0;
    std::set<int> taskThreads;
    for (const nlohmann::json& e : complete) {
        EXPECT_EQ(e["args"]["frame"], 7);
        if (e["name"] == "static phase") {
            EXPECT_DOUBLE_EQ(e["dur"].get<double>(), 2500.0);
            if (e["pid"] == 1) {
                ++onPhaseTrack;
                EXPECT_EQ(e["tid"], static_cast<int>(PhaseKind::Static));
                EXPECT_EQ(trackNames.at({1, e["tid"].get<int>()}), "static phase");
            } else {
                EXPECT_EQ(e["tid"], 0);  // the thread that made the recorder
            }
            staticStart = e["ts"].get<double>();
        } else {
            // Tasks: on the workers' tracks only, named with their object.
            EXPECT_EQ(e["pid"], 2);
            EXPECT_NE(e["tid"], 0);
            taskThreads.insert(e["tid"].get<int>());
            EXPECT_DOUBLE_EQ(e["dur"].get<double>(), 800.0);
            const std::string object = e["args"]["object"];
            EXPECT_EQ(e["name"], "build " + object);
            EXPECT_EQ(trackNames.at({2, e["tid"].get<int>()}),
                      "worker " + std::to_string(e["tid"].get<int>()));
        }
    }
    EXPECT_EQ(onPhaseTrack, 1);
    EXPECT_EQ(taskThreads, (std::set<int>{1, 2}));
    // Relative times survive: the tasks began 200 us after the phase.
    for (const nlohmann::json& e : complete) {
        if (e["name"] != "static phase") {
            EXPECT_NEAR(e["ts"].get<double>() - staticStart, 200.0, 1e-3);
        }
    }
    EXPECT_GE(staticStart, 0.0);
}

}  // namespace
}  // namespace mpshade
