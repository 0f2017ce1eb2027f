#include "phases/dicing.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <unordered_map>

#include <opensubdiv/bfr/parameterization.h>
#include <opensubdiv/bfr/tessellation.h>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

namespace mpshade {
namespace {

using namespace OpenSubdiv;

constexpr int kGrid = 8;  // segments per side of the chart survey grid

// Welds positions that quantize to within one step of each other on every axis: the same
// surface point evaluated from two charts differs only by float rounding.
class Welder {
  public:
    Welder(const FixedPointFormat& f, DicedSurface& out) : format_(f), out_(out) {}

    uint32_t weld(const glm::vec3& p) {
        const uint16_t q[3] = {format_.quantize(p.x, 0), format_.quantize(p.y, 1),
                               format_.quantize(p.z, 2)};
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int x = q[0] + dx, y = q[1] + dy, z = q[2] + dz;
                    if (x < 0 || y < 0 || z < 0 || x > 65535 || y > 65535 || z > 65535) continue;
                    auto it = map_.find(key(x, y, z));
                    if (it != map_.end()) return it->second;
                }
        return add(q);
    }

    uint32_t add(const uint16_t q[3]) {
        const uint32_t id = static_cast<uint32_t>(out_.qx.size());
        out_.qx.push_back(q[0]);
        out_.qy.push_back(q[1]);
        out_.qz.push_back(q[2]);
        map_.emplace(key(q[0], q[1], q[2]), id);
        return id;
    }

    uint32_t addUnwelded(const glm::vec3& p) {
        const uint16_t q[3] = {format_.quantize(p.x, 0), format_.quantize(p.y, 1),
                               format_.quantize(p.z, 2)};
        const uint32_t id = static_cast<uint32_t>(out_.qx.size());
        out_.qx.push_back(q[0]);
        out_.qy.push_back(q[1]);
        out_.qz.push_back(q[2]);
        return id;
    }

  private:
    static uint64_t key(int x, int y, int z) {
        return (static_cast<uint64_t>(x) << 32) | (static_cast<uint64_t>(y) << 16) |
               static_cast<uint64_t>(z);
    }
    const FixedPointFormat& format_;
    DicedSurface& out_;
    std::unordered_map<uint64_t, uint32_t> map_;
};

// The viewpoints of the range, around the object's centre c: directions within `angle` of
// the representative one, at distances from |eye - c| / factor to |eye - c| * factor.
struct EyeSet {
    glm::vec3 center;
    glm::vec3 axis;  // unit, towards the representative eye
    float r0, r1;    // distance bounds
    float angle;     // radians

    // The closest any eye comes to point p (exact for the spherical-shell sector).
    float closest(const glm::vec3& p) const {
        const glm::vec3 d = p - center;
        const float rho = glm::length(d);
        if (!(rho > 0.0f)) return r0;
        const float phi =
            std::max(0.0f, std::acos(std::clamp(glm::dot(d / rho, axis), -1.0f, 1.0f)) - angle);
        const float c = std::cos(phi);
        const float r = std::clamp(rho * c, r0, r1);
        return std::sqrt(std::max(0.0f, r * r + rho * rho - 2.0f * r * rho * c));
    }

    // The largest dot(n, e - p) over the eyes e: negative means p faces away from all of them.
    float facing(const glm::vec3& p, const glm::vec3& n) const {
        const float phi =
            std::max(0.0f, std::acos(std::clamp(glm::dot(n, axis), -1.0f, 1.0f)) - angle);
        const float c = std::cos(phi);
        return glm::dot(n, center - p) + (c >= 0.0f ? r1 : r0) * c;
    }
};

// A square piece of a chart: chart coordinates u0 + size * s, v0 + size * t.
struct Patch {
    int chart;
    float u0, v0, size;
};

struct ChartSurvey {
    bool culled = false;
    bool outsideFrustum = false;
    int desired[4] = {1, 1, 1, 1};  // per edge, Bfr order: v=0, u=1, v=1, u=0
    int innerU = 1, innerV = 1;
    uint32_t corner[4] = {};
    uint32_t middle[4] = {};  // weld id of each edge's midpoint
};

using EdgeKey = std::pair<uint32_t, uint32_t>;
EdgeKey edgeKey(uint32_t a, uint32_t b) {
    return {std::min(a, b), std::max(a, b)};
}

// A point where the chart collapses (a sphere's pole, where dP/du vanishes).
bool collapsed(const SurfaceSample& p) {
    const float du = glm::length(p.dPdu), dv = glm::length(p.dPdv);
    return du < 1e-4f * dv || dv < 1e-4f * du;
}

// How far chord a-b strays from the surface, judged at the surface point m at the chord's
// mid chart coordinates: the distance from m to the chord's midpoint, which also counts how
// far interpolated chart coordinates stray. A diagonal chord from a collapsed point has its
// mid chart coordinates off the surface's own path between a and b (at a pole, the mid u is
// another meridian), so it is not judged: the chords along the chart's lines through the
// same points are. Below float noise (the coordinates' rounding) it is zero, so a flat
// chart stays two triangles.
// Whether the surface is flat between a and b: their and m's geometric normals agree.
bool flatBetween(const SurfaceSample& a, const SurfaceSample& m, const SurfaceSample& b) {
    const float na = glm::length(a.Ng), nm = glm::length(m.Ng), nb = glm::length(b.Ng);
    if (!(na > 0.0f && nm > 0.0f && nb > 0.0f) || !std::isfinite(na + nm + nb)) return false;
    constexpr float kParallel = 1.0f - 1e-6f;  // cosine: within about 0.08 degrees
    return glm::dot(a.Ng, m.Ng) > kParallel * na * nm && glm::dot(b.Ng, m.Ng) > kParallel * nb * nm;
}

// alongNormal (DicingOptions::chartExact false): where the surface is flat between a and
// b, only the distance along its normal counts -- the facet lies on it however the chart
// coordinates run. Where it bends, the whole distance counts as before: interpolated
// normals, which shading reads, need the facets a curved chart is diced into.
float deviation(const SurfaceSample& a, const SurfaceSample& m, const SurfaceSample& b,
                bool diagonal, bool alongNormal = false) {
    if (diagonal && (collapsed(a) || collapsed(b))) return 0.0f;
    const float scale = glm::length(a.P) + glm::length(b.P) + glm::length(m.P);
    const glm::vec3 off = m.P - 0.5f * (a.P + b.P);
    const float d = alongNormal && flatBetween(a, m, b)
                        ? std::fabs(glm::dot(off, m.Ng)) / glm::length(m.Ng)
                        : glm::length(off);
    return d > 1e-6f * scale ? d : 0.0f;
}

// Bfr's quad corners: (0,0), (1,0), (1,1), (0,1); edge i runs from corner i to i + 1.
const float kCorner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};

// What the views of the range can see: their eyes, the wider set the back-face test allows
// (10 degrees more, for normals between survey points), whether back-facing patches of a
// closed surface may be dropped, and the frustum test over every view of the range.
struct RangeViews {
    EyeSet eyes, cullEyes;
    bool closed = false;
    float eyeTravel = 0.0f;  // how far an eye of the range can be from the representative one
    float frustumAngle = 0.0f;

    RangeViews(const Surface& surface, const Bounds3& bounds, const DicingView& view,
               const RangeOptions& range) {
        // Back-facing patches of a closed surface are dropped only while no eye of the range
        // can be inside its bounds or bring the near plane into it (then every face seen
        // faces away: a camera inside a dome).
        closed =
            isClosed(surface) && glm::length(view.eye - bounds.center()) / range.distanceFactor >
                                     0.5f * bounds.diagonal() + 2.0f * view.nearDistance;
        const glm::vec3 objectCenter = bounds.center();
        const float eyeDistance = std::max(glm::length(view.eye - objectCenter), 1e-20f);
        eyes.center = objectCenter;
        eyes.axis = (view.eye - objectCenter) / eyeDistance;
        eyes.r0 = eyeDistance / range.distanceFactor;
        eyes.r1 = eyeDistance * range.distanceFactor;
        eyes.angle = glm::radians(range.angle);
        cullEyes = eyes;
        cullEyes.angle = glm::radians(std::min(range.angle + 10.0f, 180.0f));
        eyeTravel = std::max(eyes.r1 - eyeDistance, eyeDistance - eyes.r0) +
                    2.0f * eyes.r1 * std::sin(0.5f * eyes.angle);
        frustumAngle = view.halfDiagonalFov + eyes.angle;
    }

    // Some view of the range may see a patch through these samples of it.
    bool maybeVisible(const DicingView& view, const std::vector<SurfaceSample>& samples) const {
        Bounds3 b;
        for (const SurfaceSample& p : samples) b.extend(p.P);
        const glm::vec3 toPatch = b.center() - view.eye;
        const float distance = glm::length(toPatch);
        const float radius = 0.5f * b.diagonal();
        if (distance <= radius + eyeTravel) return true;
        const float off =
            std::acos(std::clamp(glm::dot(toPatch / distance, view.forward), -1.0f, 1.0f));
        const float margin = std::asin(std::min(1.0f, (radius + eyeTravel) / distance));
        return off <= frustumAngle + margin;
    }
};

// The survey grid with the chord midpoints between its points: (2 kGrid + 1)^2.
constexpr int kFine = 2 * kGrid;

// Surveys one patch: whether it is culled, and the tessellation rate each of its edges and
// its interior needs, from the chords of the survey grid.
class PatchSurveyor {
  public:
    PatchSurveyor(const Surface& surface, const DicingView& view, const RangeViews& views,
                  const DicingOptions& options)
        : surface_(surface),
          view_(view),
          views_(views),
          options_(options),
          flatness_(options.target == DicingTarget::Flatness),
          chartExact_(options.chartExact),
          projected_(options.target == DicingTarget::EdgeLength && !options.overRange &&
                     view.projects),
          edgeTarget_(options.maxEdgePixels / std::sqrt(2.0f)),  // diagonals too
          grid_((kFine + 1) * (kFine + 1)),
          g_(grid_.size()) {}

    ChartSurvey survey(const Patch& patch, Welder& welder) {
        for (int j = 0; j <= kFine; ++j)
            for (int i = 0; i <= kFine; ++i)
                grid_[static_cast<size_t>(j * (kFine + 1) + i)] = {
                    patch.chart, std::min(1.0f, patch.u0 + patch.size * float(i) / kFine),
                    std::min(1.0f, patch.v0 + patch.size * float(j) / kFine)};
        evaluateBatch(surface_, grid_, g_);
        ChartSurvey sv;
        float front = -1e30f;
        for (const SurfaceSample& p : g_) front = std::max(front, views_.cullEyes.facing(p.P, p.N));
        sv.culled = views_.closed && front < 0.0f;
        if (!sv.culled && options_.frustumCull && !views_.maybeVisible(view_, g_)) {
            sv.culled = true;
            sv.outsideFrustum = true;
        }
        sv.desired[0] = line(0, 0, 1, 0);
        sv.desired[1] = line(kFine, 0, 0, 1);
        sv.desired[2] = line(0, kFine, 1, 0);
        sv.desired[3] = line(0, 0, 0, 1);
        sv.innerU = sv.innerV = 1;
        for (int j = 0; j <= kFine; j += 2) {
            sv.innerU = std::max(sv.innerU, line(0, j, 1, 0, !chartExact_));
            sv.innerV = std::max(sv.innerV, line(j, 0, 0, 1, !chartExact_));
        }
        if (flatness_) {
            // Cell diagonals: the facets' third edges.
            float most = 0.0f;
            for (int j = 0; j < kFine; j += 2)
                for (int i = 0; i < kFine; i += 2)
                    most = std::max({most, chord(i, j, 1, 1, !chartExact_),
                                     chord(i + 2, j, -1, 1, !chartExact_)});
            const int r = rate(most);
            sv.innerU = std::max(sv.innerU, r);
            sv.innerV = std::max(sv.innerV, r);
        }
        for (int c = 0; c < 4; ++c) {
            sv.corner[c] =
                welder.weld(at(int(kCorner[c][0]) * kFine, int(kCorner[c][1]) * kFine).P);
            const int n = (c + 1) % 4;
            const int mi = (int(kCorner[c][0]) + int(kCorner[n][0])) * kFine / 2;
            const int mj = (int(kCorner[c][1]) + int(kCorner[n][1])) * kFine / 2;
            sv.middle[c] = welder.weld(at(mi, mj).P);
        }
        return sv;
    }

  private:
    // Survey point (i, j), i and j in [0, 2 kGrid]: even indices are the survey grid's
    // points, odd ones the midpoints between them.
    const SurfaceSample& at(int i, int j) const {
        return g_[static_cast<size_t>(j * (kFine + 1) + i)];
    }
    // Pixels per object unit at the closest the eye comes to p (never nearer than the near
    // plane).
    float pixelsPerUnitAt(const glm::vec3& p, float halfLength) const {
        const float closest =
            options_.overRange ? views_.eyes.closest(p) : glm::length(p - view_.eye);
        return view_.pixelsPerUnit * view_.fovSlack /
               std::max(view_.nearDistance, closest - halfLength);
    }
    bool project(const glm::vec3& p, double& x, double& y) const {
        double h[3];
        for (int r = 0; r < 3; ++r)
            h[r] = view_.screen[r][0] * p.x + view_.screen[r][1] * p.y + view_.screen[r][2] * p.z +
                   view_.screen[r][3];
        if (!(h[2] > view_.nearW)) return false;
        x = h[0] / h[2], y = h[1] / h[2];
        return true;
    }
    // The chord from survey point (i0, j0) to (i0 + 2 di, j0 + 2 dj) in pixels: its length
    // (EdgeLength), or its midpoint's deviation from the surface (Flatness).
    float chord(int i0, int j0, int di, int dj, bool alongNormal = false) const {
        const SurfaceSample &a = at(i0, j0), &m = at(i0 + di, j0 + dj),
                            &b = at(i0 + 2 * di, j0 + 2 * dj);
        double ax, ay, mx, my, bx, by;
        if (projected_ && project(a.P, ax, ay) && project(m.P, mx, my) && project(b.P, bx, by))
            return static_cast<float>(std::hypot(mx - ax, my - ay) + std::hypot(bx - mx, by - my));
        const float length = glm::length(m.P - a.P) + glm::length(b.P - m.P);
        const float scale = pixelsPerUnitAt(m.P, 0.5f * length);
        if (!flatness_) return length * scale;
        return deviation(a, m, b, di != 0 && dj != 0, alongNormal) * scale;
    }
    int rate(float maxPixels) const {
        const float r = flatness_ ? kGrid * std::sqrt(maxPixels / options_.flatnessPixels)
                                  : kGrid * maxPixels / edgeTarget_;
        return static_cast<int>(std::clamp(std::ceil(r), 1.0f, 1e6f));
    }
    // The rate a line of kGrid chords needs. Its facets split every chord alike (the
    // tessellation is uniform in the chart), so the longest chord -- or the one deviating
    // most -- decides.
    int line(int i0, int j0, int di, int dj, bool alongNormal = false) const {
        float most = 0.0f;
        for (int k = 0; k < kGrid; ++k)
            most = std::max(most, chord(i0 + 2 * k * di, j0 + 2 * k * dj, di, dj, alongNormal));
        return rate(most);
    }

    const Surface& surface_;
    const DicingView& view_;
    const RangeViews& views_;
    const DicingOptions& options_;
    const bool flatness_, chartExact_, projected_;
    const float edgeTarget_;
    std::vector<ChartPoint> grid_;
    std::vector<SurfaceSample> g_;
};

// The highest rate a patch that is drawn needs.
int worstRate(const ChartSurvey& sv) {
    return sv.culled ? 0
                     : std::max({sv.desired[0], sv.desired[1], sv.desired[2], sv.desired[3],
                                 sv.innerU, sv.innerV});
}

// Step 1: every chart split into 2^d x 2^d patches (the same d for the whole object, so
// shared edges split alike) until no patch needs more than the rate cap, and each surveyed.
// Returns false, with the estimate in `out`, for DicingOptions::surveyOnly.
bool surveyPatches(const Surface& surface, const DicingView& view, const RangeViews& views,
                   const DicingOptions& options, std::vector<Patch>& patches,
                   std::vector<ChartSurvey>& survey, DicedSurface& out) {
    PatchSurveyor surveyor(surface, view, views, options);
    for (int depth = 0;; ++depth) {
        const int split = 1 << depth;
        patches.clear();
        for (int chart = 0; chart < out.charts; ++chart)
            for (int j = 0; j < split; ++j)
                for (int i = 0; i < split; ++i)
                    patches.push_back({chart, float(i) / split, float(j) / split, 1.0f / split});
        survey.assign(patches.size(), {});
        Welder welder(out.format, out);
        out.qx.clear(), out.qy.clear(), out.qz.clear();
        int worst = 0;
        for (size_t pi = 0; pi < patches.size(); ++pi) {
            survey[pi] = surveyor.survey(patches[pi], welder);
            worst = std::max(worst, worstRate(survey[pi]));
        }
        if (options.surveyOnly) {
            // The estimate from the whole charts' rates, uncapped: no splitting needed.
            out.patches = static_cast<int>(patches.size());
            for (const ChartSurvey& sv : survey)
                if (!sv.culled)
                    out.estimatedFacets += 2.0 *
                                           std::max({sv.innerU, sv.desired[0], sv.desired[2]}) *
                                           std::max({sv.innerV, sv.desired[1], sv.desired[3]});
            return false;
        }
        if (worst <= options.maxEdgeRate || depth >= options.maxSplitDepth ||
            patches.size() * 4 > static_cast<size_t>(options.maxPatches))
            return true;
    }
}

// The patches' corner and edge-midpoint ids again, in the final welder.
void weldPatchCorners(const Surface& surface, const std::vector<Patch>& patches,
                      std::vector<ChartSurvey>& survey, Welder& welder) {
    for (size_t pi = 0; pi < patches.size(); ++pi) {
        const Patch& patch = patches[pi];
        for (int c = 0; c < 4; ++c) {
            const int n = (c + 1) % 4;
            const ChartPoint corner{patch.chart,
                                    std::min(1.0f, patch.u0 + patch.size * kCorner[c][0]),
                                    std::min(1.0f, patch.v0 + patch.size * kCorner[c][1])};
            const ChartPoint middle{
                patch.chart,
                std::min(1.0f, patch.u0 + patch.size * 0.5f * (kCorner[c][0] + kCorner[n][0])),
                std::min(1.0f, patch.v0 + patch.size * 0.5f * (kCorner[c][1] + kCorner[n][1]))};
            survey[pi].corner[c] = welder.weld(evaluate(surface, corner).P);
            survey[pi].middle[c] = welder.weld(evaluate(surface, middle).P);
        }
    }
}

// Step 2: rates both sides of a shared edge agree on. An edge whose halves are edges of
// other charts (a quad beside an n-gon's sub-faces) gets an even rate, and the halves half
// of it, so the vertices coincide.
std::map<EdgeKey, int> agreeEdgeRates(const std::vector<ChartSurvey>& survey) {
    std::map<EdgeKey, int> rateOf;
    for (const ChartSurvey& s : survey)
        for (int e = 0; e < 4; ++e) {
            int& r = rateOf[edgeKey(s.corner[e], s.corner[(e + 1) % 4])];
            r = std::max(r, s.desired[e]);
        }
    for (const ChartSurvey& s : survey)
        for (int e = 0; e < 4; ++e) {
            const uint32_t a = s.corner[e], b = s.corner[(e + 1) % 4], m = s.middle[e];
            if (a == b || m == a || m == b) continue;
            auto h1 = rateOf.find(edgeKey(a, m)), h2 = rateOf.find(edgeKey(m, b));
            if (h1 == rateOf.end() && h2 == rateOf.end()) continue;
            int& full = rateOf[edgeKey(a, b)];
            const int half = std::max({(full + 1) / 2, h1 == rateOf.end() ? 0 : h1->second,
                                       h2 == rateOf.end() ? 0 : h2->second});
            full = 2 * half;
            if (h1 != rateOf.end()) h1->second = half;
            if (h2 != rateOf.end()) h2->second = half;
        }
    return rateOf;
}

// The facet budget: every rate scaled alike when the total would exceed it.
void applyFacetBudget(const DicingOptions& options, std::map<EdgeKey, int>& rateOf,
                      std::vector<ChartSurvey>& survey, DicedSurface& out) {
    double estimate = 0.0;
    for (const ChartSurvey& sv : survey) {
        if (sv.culled) continue;
        const auto edgeRate = [&](int e) {
            return rateOf[edgeKey(sv.corner[e], sv.corner[(e + 1) % 4])];
        };
        const int ru =
            std::min(std::max({sv.innerU, edgeRate(0), edgeRate(2)}), options.maxEdgeRate);
        const int rv =
            std::min(std::max({sv.innerV, edgeRate(1), edgeRate(3)}), options.maxEdgeRate);
        estimate += 2.0 * ru * rv;
    }
    out.estimatedFacets = estimate;
    if (estimate <= static_cast<double>(options.maxFacets)) return;
    out.rateScale =
        static_cast<float>(std::sqrt(static_cast<double>(options.maxFacets) / estimate));
    auto scaled = [&](int r) {
        return std::max(1, static_cast<int>(std::floor(r * out.rateScale)));
    };
    for (auto& [key, r] : rateOf) r = scaled(std::min(r, options.maxEdgeRate));
    for (ChartSurvey& sv : survey)
        sv.innerU = scaled(std::min(sv.innerU, options.maxEdgeRate)),
        sv.innerV = scaled(std::min(sv.innerV, options.maxEdgeRate));
}

// Bounding sphere and normal cone of a patch's vertices (geometric normals).
void boundCluster(const std::vector<SurfaceSample>& samples, size_t n, FacetCluster& cluster) {
    Bounds3 box;
    glm::vec3 axis(0.0f);
    for (size_t k = 0; k < n; ++k) box.extend(samples[k].P), axis += samples[k].Ng;
    cluster.center = box.center();
    for (size_t k = 0; k < n; ++k)
        cluster.radius = std::max(cluster.radius, glm::length(samples[k].P - cluster.center));
    const float axisLength = glm::length(axis);
    if (axisLength > 0.0f) {
        cluster.coneAxis = axis / axisLength;
        float minCos = 1.0f;
        for (size_t k = 0; k < n; ++k)
            minCos = std::min(minCos, glm::dot(samples[k].Ng, cluster.coneAxis));
        // Facets are chords between the vertices: allow a little more than the vertices' own
        // normals span.
        cluster.coneHalfAngle = std::acos(std::clamp(minCos, -1.0f, 1.0f)) + 0.05f;
    }
}

// Step 3: each visible patch tessellated with its agreed edge rates, one cluster per patch.
class PatchTessellator {
  public:
    PatchTessellator(const Surface& surface, const DicingOptions& options, DicedSurface& out,
                     Welder& welder)
        : surface_(surface), options_(options), out_(out), welder_(welder) {
        tessOptions_.SetFacetSize(3);
    }

    void tessellate(const Patch& patch, const ChartSurvey& s, std::map<EdgeKey, int>& rateOf) {
        if (s.culled) {
            ++(s.outsideFrustum ? out_.frustumCulled : out_.culledCharts);
            return;
        }
        int rates[6];
        bool capped = false;
        for (int e = 0; e < 4; ++e) {
            rates[e] = rateOf[edgeKey(s.corner[e], s.corner[(e + 1) % 4])];
            capped = capped || rates[e] > options_.maxEdgeRate;
            rates[e] = std::min(rates[e], options_.maxEdgeRate);
        }
        rates[4] = std::min(std::max({s.innerU, rates[0], rates[2]}), options_.maxEdgeRate);
        rates[5] = std::min(std::max({s.innerV, rates[1], rates[3]}), options_.maxEdgeRate);
        // Halving keeps both sides of an edge on the same vertices only if they agree, so a
        // capped rate still equals its neighbour's capped rate.
        if (capped || s.innerU > options_.maxEdgeRate || s.innerV > options_.maxEdgeRate ||
            out_.rateScale < 1.0f)
            ++out_.cappedCharts;
        Bfr::Tessellation tess(quad_, 6, rates, tessOptions_);
        coords_.resize(static_cast<size_t>(tess.GetNumCoords()) * 2);
        tess.GetCoords(coords_.data());
        facets_.resize(static_cast<size_t>(tess.GetNumFacets()) * 3);
        tess.GetFacets(facets_.data());
        const size_t n = static_cast<size_t>(tess.GetNumCoords());
        points_.resize(n);
        for (size_t k = 0; k < n; ++k)
            points_[k] = {patch.chart,
                          std::clamp(patch.u0 + patch.size * coords_[2 * k], 0.0f, 1.0f),
                          std::clamp(patch.v0 + patch.size * coords_[2 * k + 1], 0.0f, 1.0f)};
        samples_.resize(n);
        evaluateBatch(surface_, points_, samples_);
        const uint32_t base = static_cast<uint32_t>(out_.attributePoints.size());
        const size_t boundary = static_cast<size_t>(tess.GetNumBoundaryCoords());
        for (size_t k = 0; k < n; ++k) {
            out_.attributePoints.push_back(points_[k]);
            out_.attributeGeometry.push_back(samples_[k]);
            out_.positionOf.push_back(k < boundary ? welder_.weld(samples_[k].P)
                                                   : welder_.addUnwelded(samples_[k].P));
        }
        FacetCluster cluster;
        cluster.firstFacet = static_cast<uint32_t>(out_.triangles.size() / 3);
        for (int f : facets_) out_.triangles.push_back(base + static_cast<uint32_t>(f));
        cluster.facetCount = static_cast<uint32_t>(out_.triangles.size() / 3) - cluster.firstFacet;
        boundCluster(samples_, n, cluster);
        out_.clusters.push_back(cluster);
    }

  private:
    const Surface& surface_;
    const DicingOptions& options_;
    DicedSurface& out_;
    Welder& welder_;
    const Bfr::Parameterization quad_{Sdc::SCHEME_CATMARK, 4};  // the unit square
    Bfr::Tessellation::Options tessOptions_;
    std::vector<float> coords_;
    std::vector<int> facets_;
    std::vector<ChartPoint> points_;
    std::vector<SurfaceSample> samples_;
};

// Drops the positions no facet uses (survey corners and edge midpoints, welded only to
// match shared edges), so the warp transforms only what is drawn.
void dropUnusedPositions(DicedSurface& out) {
    std::vector<uint32_t> remap(out.qx.size(), UINT32_MAX);
    std::vector<uint16_t> qx, qy, qz;
    for (uint32_t& p : out.positionOf) {
        if (remap[p] == UINT32_MAX) {
            remap[p] = static_cast<uint32_t>(qx.size());
            qx.push_back(out.qx[p]), qy.push_back(out.qy[p]), qz.push_back(out.qz[p]);
        }
        p = remap[p];
    }
    out.qx = std::move(qx), out.qy = std::move(qy), out.qz = std::move(qz);
}

}  // namespace

DicedSurface diceSurface(const Surface& surface, const DicingView& view, const RangeOptions& range,
                         const DicingOptions& options) {
    DicedSurface out;
    const Bounds3 bounds = surfaceBounds(surface);
    out.format = FixedPointFormat::forBounds(bounds);
    out.charts = chartCount(surface);
    const RangeViews views(surface, bounds, view, range);
    std::vector<Patch> patches;
    std::vector<ChartSurvey> survey;
    if (!surveyPatches(surface, view, views, options, patches, survey, out)) return out;
    out.patches = static_cast<int>(patches.size());
    Welder welder(out.format, out);
    out.qx.clear(), out.qy.clear(), out.qz.clear();
    weldPatchCorners(surface, patches, survey, welder);
    std::map<EdgeKey, int> rateOf = agreeEdgeRates(survey);
    applyFacetBudget(options, rateOf, survey, out);
    PatchTessellator tessellator(surface, options, out, welder);
    for (size_t pi = 0; pi < patches.size(); ++pi)
        tessellator.tessellate(patches[pi], survey[pi], rateOf);
    dropUnusedPositions(out);
    return out;
}

}  // namespace mpshade
