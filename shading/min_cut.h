// min_cut.h -- maximum flow / minimum cut on a small directed graph (Dinic's algorithm).
// The factoring uses it to choose the n-tuple: the fewest stored values that separate the
// static work from the dynamic consumers.
#pragma once

#include <cstdint>
#include <vector>

namespace mpshade {

class FlowGraph {
  public:
    static constexpr int64_t kInfinite = int64_t{1} << 40;

    int addNode();
    void addEdge(int from, int to, int64_t capacity);
    // Pushes the maximum flow from s to t; returns its value.
    int64_t maxFlow(int s, int t);
    // After maxFlow: the nodes that can still reach t through residual capacity. A
    // minimum cut is every saturated edge from outside this set into it; taking this set
    // gives the cut closest to t.
    std::vector<char> reachesSink(int t) const;
    int nodeCount() const { return static_cast<int>(head_.size()); }

  private:
    struct Edge {
        int to;
        int64_t capacity;
    };
    bool levelGraph(int s, int t);
    int64_t push(int u, int t, int64_t limit);

    std::vector<Edge> edges_;             // edge e and its reverse e ^ 1
    std::vector<std::vector<int>> head_;  // edges leaving each node
    std::vector<int> level_, next_;
};

}  // namespace mpshade
