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
float deviation(const SurfaceSample& a, const SurfaceSample& m, const SurfaceSample& b,
                bool diagonal) {
    if (diagonal && (collapsed(a) || collapsed(b))) return 0.0f;
    const float scale = glm::length(a.P) + glm::length(b.P) + glm::length(m.P);
    const float d = glm::length(m.P - 0.5f * (a.P + b.P));
    return d > 1e-6f * scale ? d : 0.0f;
}

// Bfr's quad corners: (0,0), (1,0), (1,1), (0,1); edge i runs from corner i to i + 1.
const float kCorner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};

}  // namespace

DicedSurface diceSurface(const Surface& surface, const DicingView& view, const RangeOptions& range,
                         const DicingOptions& options) {
    DicedSurface out;
    const Bounds3 bounds = surfaceBounds(surface);
    out.format = FixedPointFormat::forBounds(bounds);
    const int charts = chartCount(surface);
    out.charts = charts;
    // Back-facing patches of a closed surface are dropped only while no eye of the range
    // can be inside its bounds or bring the near plane into it (then every face seen faces
    // away: a camera inside a dome).
    const bool closed =
        isClosed(surface) && glm::length(view.eye - bounds.center()) / range.distanceFactor >
                                 0.5f * bounds.diagonal() + 2.0f * view.nearDistance;
    const glm::vec3 objectCenter = bounds.center();
    const float eyeDistance = std::max(glm::length(view.eye - objectCenter), 1e-20f);
    EyeSet eyes;
    eyes.center = objectCenter;
    eyes.axis = (view.eye - objectCenter) / eyeDistance;
    eyes.r0 = eyeDistance / range.distanceFactor;
    eyes.r1 = eyeDistance * range.distanceFactor;
    eyes.angle = glm::radians(range.angle);
    // The back-face test allows 10 degrees more, for normals between survey points.
    EyeSet cullEyes = eyes;
    cullEyes.angle = glm::radians(std::min(range.angle + 10.0f, 180.0f));
    // How far an eye of the range can be from the representative one: for the frustum test.
    const float eyeTravel = std::max(eyes.r1 - eyeDistance, eyeDistance - eyes.r0) +
                            2.0f * eyes.r1 * std::sin(0.5f * eyes.angle);
    const float frustumAngle = view.halfDiagonalFov + eyes.angle;
    auto maybeVisible = [&](const std::vector<SurfaceSample>& samples) {
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
    };

    // 1. Survey every patch; split every chart into 2^d x 2^d patches (the same d for the
    //    whole object, so shared edges split alike) until no patch needs more than the
    //    rate cap.
    std::vector<Patch> patches;
    std::vector<ChartSurvey> survey;
    // The survey grid with the chord midpoints between its points: (2 kGrid + 1)^2.
    constexpr int kFine = 2 * kGrid;
    std::vector<ChartPoint> grid((kFine + 1) * (kFine + 1));
    std::vector<SurfaceSample> g(grid.size());
    for (int depth = 0;; ++depth) {
        const int split = 1 << depth;
        patches.clear();
        for (int chart = 0; chart < charts; ++chart)
            for (int j = 0; j < split; ++j)
                for (int i = 0; i < split; ++i)
                    patches.push_back({chart, float(i) / split, float(j) / split, 1.0f / split});
        survey.assign(patches.size(), {});
        Welder welder(out.format, out);
        out.qx.clear(), out.qy.clear(), out.qz.clear();
        int worst = 0;
        for (size_t pi = 0; pi < patches.size(); ++pi) {
            const Patch& patch = patches[pi];
            for (int j = 0; j <= kFine; ++j)
                for (int i = 0; i <= kFine; ++i)
                    grid[static_cast<size_t>(j * (kFine + 1) + i)] = {
                        patch.chart, std::min(1.0f, patch.u0 + patch.size * float(i) / kFine),
                        std::min(1.0f, patch.v0 + patch.size * float(j) / kFine)};
            evaluateBatch(surface, grid, g);
            // Survey point (i, j), i and j in [0, 2 kGrid]: even indices are the survey
            // grid's points, odd ones the midpoints between them.
            auto at = [&](int i, int j) -> const SurfaceSample& {
                return g[static_cast<size_t>(j * (kFine + 1) + i)];
            };
            ChartSurvey& sv = survey[pi];
            float front = -1e30f;
            for (const SurfaceSample& p : g) front = std::max(front, cullEyes.facing(p.P, p.N));
            sv.culled = closed && front < 0.0f;
            if (!sv.culled && options.frustumCull && !maybeVisible(g)) {
                sv.culled = true;
                sv.outsideFrustum = true;
            }
            // Each survey chord in pixels at the closest the eye comes to it (never nearer
            // than the near plane): its length (EdgeLength), or its midpoint's deviation
            // from the surface (Flatness).
            auto pixelsPerUnitAt = [&](const glm::vec3& p, float halfLength) {
                const float closest =
                    options.overRange ? eyes.closest(p) : glm::length(p - view.eye);
                return view.pixelsPerUnit * view.fovSlack /
                       std::max(view.nearDistance, closest - halfLength);
            };
            const bool flatness = options.target == DicingTarget::Flatness;
            // Chord from survey point (i0, j0) to (i0 + 2 di, j0 + 2 dj).
            const bool projected =
                options.target == DicingTarget::EdgeLength && !options.overRange && view.projects;
            auto project = [&](const glm::vec3& p, double& x, double& y) {
                double h[3];
                for (int r = 0; r < 3; ++r)
                    h[r] = view.screen[r][0] * p.x + view.screen[r][1] * p.y +
                           view.screen[r][2] * p.z + view.screen[r][3];
                if (!(h[2] > view.nearW)) return false;
                x = h[0] / h[2], y = h[1] / h[2];
                return true;
            };
            auto chord = [&](int i0, int j0, int di, int dj) {
                const SurfaceSample &a = at(i0, j0), &m = at(i0 + di, j0 + dj),
                                    &b = at(i0 + 2 * di, j0 + 2 * dj);
                double ax, ay, mx, my, bx, by;
                if (projected && project(a.P, ax, ay) && project(m.P, mx, my) &&
                    project(b.P, bx, by))
                    return static_cast<float>(std::hypot(mx - ax, my - ay) +
                                              std::hypot(bx - mx, by - my));
                const float length = glm::length(m.P - a.P) + glm::length(b.P - m.P);
                const float scale = pixelsPerUnitAt(m.P, 0.5f * length);
                if (!flatness) return length * scale;
                return deviation(a, m, b, di != 0 && dj != 0) * scale;
            };
            // The rate a line of kGrid chords needs. Its facets split every chord alike (the
            // tessellation is uniform in the chart), so the longest chord -- or the one
            // deviating most -- decides.
            const float edgeTarget = options.maxEdgePixels / std::sqrt(2.0f);  // diagonals too
            auto rate = [&](float maxPixels) {
                const float r = flatness ? kGrid * std::sqrt(maxPixels / options.flatnessPixels)
                                         : kGrid * maxPixels / edgeTarget;
                return static_cast<int>(std::clamp(std::ceil(r), 1.0f, 1e6f));
            };
            auto line = [&](int i0, int j0, int di, int dj) {
                float most = 0.0f;
                for (int k = 0; k < kGrid; ++k)
                    most = std::max(most, chord(i0 + 2 * k * di, j0 + 2 * k * dj, di, dj));
                return rate(most);
            };
            sv.desired[0] = line(0, 0, 1, 0);
            sv.desired[1] = line(kFine, 0, 0, 1);
            sv.desired[2] = line(0, kFine, 1, 0);
            sv.desired[3] = line(0, 0, 0, 1);
            sv.innerU = sv.innerV = 1;
            for (int j = 0; j <= kFine; j += 2) {
                sv.innerU = std::max(sv.innerU, line(0, j, 1, 0));
                sv.innerV = std::max(sv.innerV, line(j, 0, 0, 1));
            }
            if (flatness) {
                // Cell diagonals: the facets' third edges.
                float most = 0.0f;
                for (int j = 0; j < kFine; j += 2)
                    for (int i = 0; i < kFine; i += 2)
                        most = std::max({most, chord(i, j, 1, 1), chord(i + 2, j, -1, 1)});
                const int r = rate(most);
                sv.innerU = std::max(sv.innerU, r);
                sv.innerV = std::max(sv.innerV, r);
            }
            if (!sv.culled)
                worst = std::max({worst, sv.desired[0], sv.desired[1], sv.desired[2], sv.desired[3],
                                  sv.innerU, sv.innerV});
            for (int c = 0; c < 4; ++c) {
                sv.corner[c] =
                    welder.weld(at(int(kCorner[c][0]) * kFine, int(kCorner[c][1]) * kFine).P);
                const int n = (c + 1) % 4;
                const int mi = (int(kCorner[c][0]) + int(kCorner[n][0])) * kFine / 2;
                const int mj = (int(kCorner[c][1]) + int(kCorner[n][1])) * kFine / 2;
                sv.middle[c] = welder.weld(at(mi, mj).P);
            }
        }
        if (options.surveyOnly) {
            // The estimate from the whole charts' rates, uncapped: no splitting needed.
            out.patches = static_cast<int>(patches.size());
            for (const ChartSurvey& sv : survey)
                if (!sv.culled)
                    out.estimatedFacets += 2.0 *
                                           std::max({sv.innerU, sv.desired[0], sv.desired[2]}) *
                                           std::max({sv.innerV, sv.desired[1], sv.desired[3]});
            return out;
        }
        if (worst <= options.maxEdgeRate || depth >= options.maxSplitDepth ||
            patches.size() * 4 > static_cast<size_t>(options.maxPatches))
            break;
    }
    out.patches = static_cast<int>(patches.size());
    Welder welder(out.format, out);
    out.qx.clear(), out.qy.clear(), out.qz.clear();
    // Corner and midpoint ids again, in the final welder.
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

    // 2. Rates both sides of a shared edge agree on. An edge whose halves are edges of
    //    other charts (a quad beside an n-gon's sub-faces) gets an even rate, and the halves
    //    half of it, so the vertices coincide.
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

    // The facet budget: scale every rate alike when the total would exceed it.
    auto innerRates = [&](const ChartSurvey& sv, int& ru, int& rv) {
        const auto edgeRate = [&](int e) {
            return rateOf[edgeKey(sv.corner[e], sv.corner[(e + 1) % 4])];
        };
        ru = std::min(std::max({sv.innerU, edgeRate(0), edgeRate(2)}), options.maxEdgeRate);
        rv = std::min(std::max({sv.innerV, edgeRate(1), edgeRate(3)}), options.maxEdgeRate);
    };
    double estimate = 0.0;
    for (const ChartSurvey& sv : survey) {
        if (sv.culled) continue;
        int ru, rv;
        innerRates(sv, ru, rv);
        estimate += 2.0 * ru * rv;
    }
    out.estimatedFacets = estimate;
    if (estimate > static_cast<double>(options.maxFacets)) {
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

    // 3. Tessellate each visible chart with its agreed edge rates.
    const Bfr::Parameterization quad(Sdc::SCHEME_CATMARK, 4);  // the unit square
    Bfr::Tessellation::Options tessOptions;
    tessOptions.SetFacetSize(3);
    std::vector<float> coords;
    std::vector<int> facets;
    std::vector<ChartPoint> points;
    std::vector<SurfaceSample> samples;
    for (size_t pi = 0; pi < patches.size(); ++pi) {
        const Patch& patch = patches[pi];
        const ChartSurvey& s = survey[pi];
        if (s.culled) {
            ++(s.outsideFrustum ? out.frustumCulled : out.culledCharts);
            continue;
        }
        int rates[6];
        bool capped = false;
        for (int e = 0; e < 4; ++e) {
            rates[e] = rateOf[edgeKey(s.corner[e], s.corner[(e + 1) % 4])];
            capped = capped || rates[e] > options.maxEdgeRate;
            rates[e] = std::min(rates[e], options.maxEdgeRate);
        }
        rates[4] = std::min(std::max({s.innerU, rates[0], rates[2]}), options.maxEdgeRate);
        rates[5] = std::min(std::max({s.innerV, rates[1], rates[3]}), options.maxEdgeRate);
        capped = capped || s.innerU > options.maxEdgeRate || s.innerV > options.maxEdgeRate ||
                 out.rateScale < 1.0f;
        if (capped) {
            // Halving keeps both sides of an edge on the same vertices only if they agree,
            // so a capped rate still equals its neighbour's capped rate.
            ++out.cappedCharts;
        }
        Bfr::Tessellation tess(quad, 6, rates, tessOptions);
        coords.resize(static_cast<size_t>(tess.GetNumCoords()) * 2);
        tess.GetCoords(coords.data());
        facets.resize(static_cast<size_t>(tess.GetNumFacets()) * 3);
        tess.GetFacets(facets.data());
        const size_t n = static_cast<size_t>(tess.GetNumCoords());
        points.resize(n);
        for (size_t k = 0; k < n; ++k)
            points[k] = {patch.chart, std::clamp(patch.u0 + patch.size * coords[2 * k], 0.0f, 1.0f),
                         std::clamp(patch.v0 + patch.size * coords[2 * k + 1], 0.0f, 1.0f)};
        samples.resize(n);
        evaluateBatch(surface, points, samples);
        const uint32_t base = static_cast<uint32_t>(out.attributePoints.size());
        const size_t boundary = static_cast<size_t>(tess.GetNumBoundaryCoords());
        for (size_t k = 0; k < n; ++k) {
            out.attributePoints.push_back(points[k]);
            out.attributeGeometry.push_back(samples[k]);
            out.positionOf.push_back(k < boundary ? welder.weld(samples[k].P)
                                                  : welder.addUnwelded(samples[k].P));
        }
        FacetCluster cluster;
        cluster.firstFacet = static_cast<uint32_t>(out.triangles.size() / 3);
        for (int f : facets) out.triangles.push_back(base + static_cast<uint32_t>(f));
        cluster.facetCount = static_cast<uint32_t>(out.triangles.size() / 3) - cluster.firstFacet;
        // Bounding sphere and normal cone of the patch's vertices (geometric normals).
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
            // Facets are chords between the vertices: allow a little more than the vertices'
            // own normals span.
            cluster.coneHalfAngle = std::acos(std::clamp(minCos, -1.0f, 1.0f)) + 0.05f;
        }
        out.clusters.push_back(cluster);
    }
    // Drop the positions no facet uses (survey corners and edge midpoints, welded only to
    // match shared edges), so the warp transforms only what is drawn.
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
    return out;
}

}  // namespace mpshade
