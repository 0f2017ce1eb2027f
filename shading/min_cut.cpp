#include "shading/min_cut.h"

#include <algorithm>
#include <deque>

namespace mpshade {

int FlowGraph::addNode() {
    head_.emplace_back();
    return static_cast<int>(head_.size()) - 1;
}

void FlowGraph::addEdge(int from, int to, int64_t capacity) {
    head_[static_cast<size_t>(from)].push_back(static_cast<int>(edges_.size()));
    edges_.push_back({to, capacity});
    head_[static_cast<size_t>(to)].push_back(static_cast<int>(edges_.size()));
    edges_.push_back({from, 0});
}

bool FlowGraph::levelGraph(int s, int t) {
    level_.assign(head_.size(), -1);
    std::deque<int> queue{s};
    level_[static_cast<size_t>(s)] = 0;
    while (!queue.empty()) {
        const int u = queue.front();
        queue.pop_front();
        for (int e : head_[static_cast<size_t>(u)]) {
            const Edge& edge = edges_[static_cast<size_t>(e)];
            if (edge.capacity > 0 && level_[static_cast<size_t>(edge.to)] < 0) {
                level_[static_cast<size_t>(edge.to)] = level_[static_cast<size_t>(u)] + 1;
                queue.push_back(edge.to);
            }
        }
    }
    return level_[static_cast<size_t>(t)] >= 0;
}

int64_t FlowGraph::push(int u, int t, int64_t limit) {
    if (u == t) return limit;
    auto& out = head_[static_cast<size_t>(u)];
    for (int& i = next_[static_cast<size_t>(u)]; i < static_cast<int>(out.size()); ++i) {
        const int e = out[static_cast<size_t>(i)];
        Edge& edge = edges_[static_cast<size_t>(e)];
        if (edge.capacity <= 0 ||
            level_[static_cast<size_t>(edge.to)] != level_[static_cast<size_t>(u)] + 1)
            continue;
        const int64_t pushed = push(edge.to, t, std::min(limit, edge.capacity));
        if (pushed > 0) {
            edge.capacity -= pushed;
            edges_[static_cast<size_t>(e ^ 1)].capacity += pushed;
            return pushed;
        }
    }
    return 0;
}

int64_t FlowGraph::maxFlow(int s, int t) {
    int64_t flow = 0;
    while (levelGraph(s, t)) {
        next_.assign(head_.size(), 0);
        while (const int64_t pushed = push(s, t, kInfinite)) flow += pushed;
    }
    return flow;
}

std::vector<char> FlowGraph::reachesSink(int t) const {
    // Backwards over residual edges: u reaches t if some edge u -> v has capacity left
    // and v reaches t. Edge e ^ 1 is the reverse of e, stored at v.
    std::vector<char> reaches(head_.size(), 0);
    std::deque<int> queue{t};
    reaches[static_cast<size_t>(t)] = 1;
    while (!queue.empty()) {
        const int v = queue.front();
        queue.pop_front();
        for (int r : head_[static_cast<size_t>(v)]) {
            const int e = r ^ 1;  // the edge u -> v
            const int u = edges_[static_cast<size_t>(r)].to;
            if (edges_[static_cast<size_t>(e)].capacity > 0 && !reaches[static_cast<size_t>(u)]) {
                reaches[static_cast<size_t>(u)] = 1;
                queue.push_back(u);
            }
        }
    }
    return reaches;
}

}  // namespace mpshade
