#include "phases/facet_clipping.h"

#include <cmath>
#include <utility>

namespace mpshade {
namespace {

struct ClipVertex {
    double X, Y, W;
    bool warped;  // a corner the warp kept: its warped screen position is used as it is
    uint32_t index;
};

// Signed distance to clipping plane k (inside when >= 0): the near plane, then the guard
// band's four sides.
double distance(const ClipVertex& v, int k, double nearW) {
    constexpr double G = FixedPointWarp::kGuardBand;
    switch (k) {
        case 0:
            return v.W - nearW;
        case 1:
            return G * v.W - v.X;
        case 2:
            return G * v.W + v.X;
        case 3:
            return G * v.W - v.Y;
        default:
            return G * v.W + v.Y;
    }
}

bool before(const ClipVertex& a, const ClipVertex& b) {
    if (a.X != b.X) return a.X < b.X;
    if (a.Y != b.Y) return a.Y < b.Y;
    return a.W < b.W;
}

// Where edge (a, b) crosses plane k, computed from the end points in canonical order so
// both facets sharing the edge get the same corner.
ClipVertex crossing(ClipVertex a, ClipVertex b, int k, double nearW) {
    if (before(b, a)) std::swap(a, b);
    const double da = distance(a, k, nearW), db = distance(b, k, nearW);
    const double t = da / (da - db);
    ClipVertex v{a.X + t * (b.X - a.X), a.Y + t * (b.Y - a.Y), a.W + t * (b.W - a.W), false, 0};
    if (k == 0) v.W = std::max(v.W, nearW);
    return v;
}

}  // namespace

int clipFacet(const FixedPointWarp& warp, const FacetMesh& mesh, const WarpedVertices& warped,
              const uint32_t p[3], ScreenTriangle out[6]) {
    const double nearW = warp.nearDepth();
    ClipVertex buffers[2][9];
    int n = 3;
    ClipVertex* poly = buffers[0];
    ClipVertex* next = buffers[1];
    for (int i = 0; i < 3; ++i) {
        const HomogeneousVertex h = warp.homogeneous(mesh.qx[p[i]], mesh.qy[p[i]], mesh.qz[p[i]]);
        poly[i] = {h.X, h.Y, h.W, !warped.culled(p[i]), p[i]};
    }
    for (int k = 0; k < 5 && n > 0; ++k) {
        int m = 0;
        for (int i = 0; i < n; ++i) {
            const ClipVertex& a = poly[i];
            const ClipVertex& b = poly[(i + 1) % n];
            const double da = distance(a, k, nearW), db = distance(b, k, nearW);
            if (da >= 0.0) next[m++] = a;
            if ((da >= 0.0) != (db >= 0.0)) next[m++] = crossing(a, b, k, nearW);
        }
        std::swap(poly, next);
        n = m;
    }
    if (n < 3) return 0;
    int32_t x[9], y[9];
    float invDepth[9];
    for (int i = 0; i < n; ++i) {
        const ClipVertex& v = poly[i];
        if (v.warped) {
            x[i] = warped.x[v.index];
            y[i] = warped.y[v.index];
            invDepth[i] = warped.invDepth[v.index];
        } else {
            // Inside the guard band: |X / W| <= 2^15, so 256 X / W fits int32.
            x[i] = static_cast<int32_t>(std::nearbyint(v.X * 256.0 / v.W));
            y[i] = static_cast<int32_t>(std::nearbyint(v.Y * 256.0 / v.W));
            invDepth[i] = static_cast<float>(1.0 / v.W);
        }
    }
    for (int i = 1; i + 1 < n; ++i) {
        ScreenTriangle& t = out[i - 1];
        const int c[3] = {0, i, i + 1};
        for (int j = 0; j < 3; ++j) {
            t.x[j] = x[c[j]];
            t.y[j] = y[c[j]];
            t.invDepth[j] = invDepth[c[j]];
        }
    }
    return n - 2;
}

}  // namespace mpshade
