// chart_adjacency.h -- which chart lies across each edge of each chart, so data sampled
// just beyond a chart's edge (shader-map borders) can be taken from the surface itself.
//
// Edges follow OpenSubdiv's quad convention: edge 0 is v = 0 (u from 0 to 1), edge 1 is
// u = 1 (v from 0 to 1), edge 2 is v = 1 (u from 1 to 0), edge 3 is u = 0 (v from 1 to
// 0). Two chart edges are neighbours when their end points and midpoints coincide on the
// surface (within 1e-5 of the bounding diagonal): shared cage edges, shared patch borders,
// a sphere's or torus's seam. Edges with no such partner (a plane's border, a pole, the
// outer edge of an n-gon's quad sub-face) have none, and lookups beyond them clamp.
#pragma once

#include <array>
#include <vector>

#include "geometry/surface.h"

namespace mpshade {

struct ChartEdgeLink {
    int chart = -1;        // the neighbour; -1: none
    int edge = 0;          // the neighbour's edge
    bool reversed = true;  // the neighbour runs along the shared edge the other way
};

class ChartAdjacency {
  public:
    explicit ChartAdjacency(const Surface& surface);

    const ChartEdgeLink& link(int chart, int edge) const {
        return links_[static_cast<size_t>(chart)][static_cast<size_t>(edge)];
    }

    // A chart point for (u, v), which may lie outside [0, 1]^2: across the edge it crosses
    // most, on the neighbouring chart at the same distance in from that edge; clamped
    // where there is no neighbour (or after the one step).
    ChartPoint resolve(int chart, float u, float v) const;

  private:
    std::vector<std::array<ChartEdgeLink, 4>> links_;
};

}  // namespace mpshade
