#include "phases/map_demand.h"

#include <algorithm>
#include <cmath>
#include <unordered_set>

#include <embree3/rtcore.h>
#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "shadermaps/chart_aspect.h"

namespace mpshade {
namespace {

// A grid of cells over an object's charts (k x k a chart; past the budget, every
// `stride`-th chart), with the surface at each centre, and each chart's shifts (the map's
// texels along u are R >> shift.u[chart] at level 0, chart_aspect.h).
struct ChartCells {
    int k = 1, stride = 1;
    std::vector<ChartPoint> at;
    std::vector<SurfaceSample> geometry;
    ChartShifts shift;
};

ChartCells chartCells(const Surface& surface, int budget) {
    ChartCells c;
    const int charts = chartCount(surface);
    if (charts <= 0) return c;
    c.k = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(budget) / charts)));
    c.stride = std::max(1, charts / std::max(1, budget));
    for (int chart = 0; chart < charts; chart += c.stride)
        for (int j = 0; j < c.k; ++j)
            for (int i = 0; i < c.k; ++i)
                c.at.push_back({chart, (i + 0.5f) / c.k, (j + 0.5f) / c.k});
    c.geometry.resize(c.at.size());
    evaluateBatch(surface, c.at, c.geometry);
    return c;
}

// The pixel position's derivative along the world direction `a`, at camera-space point p.
glm::dvec2 screenDerivative(const CameraState& c, double ppu, const glm::vec3& p,
                            const glm::vec3& a) {
    const double z = glm::dot(p, c.forward);
    const double x = glm::dot(p, c.right), y = glm::dot(p, c.up);
    const double dz = glm::dot(a, c.forward);
    return {ppu * (glm::dot(a, c.right) * z - x * dz) / (z * z),
            ppu * (glm::dot(a, c.up) * z - y * dz) / (z * z)};
}

// Whether a surface lies between the eye and P (the object's own included, short of P).
bool hidden(RTCScene world, const glm::vec3& eye, const glm::vec3& P) {
    const glm::vec3 d = P - eye;
    const float distance = glm::length(d);
    if (!(distance > 0.0f)) return false;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay ray{};
    ray.org_x = eye.x, ray.org_y = eye.y, ray.org_z = eye.z;
    ray.dir_x = d.x / distance, ray.dir_y = d.y / distance, ray.dir_z = d.z / distance;
    ray.tnear = 0.0f;
    // Short of P by more than the ray scene's tessellation of the surface through it.
    ray.tfar = distance * 0.98f;
    ray.mask = 0xFFFFFFFFu;
    rtcOccluded1(world, &ctx, &ray);
    return ray.tfar < 0.0f;
}

uint64_t tileId(int chart, int level, int64_t tx, int64_t ty) {
    return (static_cast<uint64_t>(chart) << 42) ^ (static_cast<uint64_t>(level) << 37) ^
           (static_cast<uint64_t>(tx) << 18) ^ static_cast<uint64_t>(ty);
}

struct FrameDemand {
    double tiles = 0.0, covered = 0.0;
    int finest = 0;
};

// A cell of the grid, or a quarter of one: its centre, the surface there, and how many
// times it was split (its side is 1 / (k 2^depth) of its chart's).
struct Cell {
    ChartPoint at;
    SurfaceSample g;
    int depth = 0;
};

// A cell is split while it spans more than this many pixels as seen from the eye, so no
// cell is counted by a centre far from most of what it covers: a floor seen at a grazing
// angle from close by, whose near cells straddle the image's edge or the near plane.
constexpr double kSplitPixels = 8.0;
constexpr int kMaxDepth = 16;
constexpr size_t kMaxCells = 1 << 18;  // per object and frame, split or not

FrameDemand frameDemand(const Surface& surface, const ChartCells& cells, const MapDemand& d,
                        int maxLevel, int tile, bool closed, const FrameState& frame,
                        const ObjectState& state, RTCScene world, double footprint,
                        const ProbeOptions& probe, std::unordered_set<uint64_t>& asked) {
    const CameraState& camera = frame.camera;
    const glm::mat3 linear(state.objectToWorld);
    const double ppu = 0.5 * camera.height / camera.tanHalfFovY;
    asked.clear();
    FrameDemand out;
    out.finest = maxLevel;
    std::vector<Cell> stack;
    for (size_t c = 0; c < cells.at.size(); ++c)
        stack.push_back({cells.at[c], cells.geometry[c], 0});
    size_t visited = 0;
    ChartPoint quarters[4];
    SurfaceSample quarterGeometry[4];
    while (!stack.empty()) {
        const Cell cell = stack.back();
        stack.pop_back();
        ++visited;
        const SurfaceSample& g = cell.g;
        const double size = 1.0 / (cells.k * double(1 << cell.depth));  // chart units a side
        const glm::vec3 P = glm::vec3(state.objectToWorld * glm::vec4(g.P, 1.0f));
        const glm::vec3 p = P - camera.eye;
        const double reach =
            0.5 * size *
            (double(glm::length(linear * g.dPdu)) + double(glm::length(linear * g.dPdv)));
        if (cell.depth < kMaxDepth && visited + stack.size() + 4 <= kMaxCells &&
            reach * ppu > kSplitPixels * double(glm::length(p))) {
            const float q = static_cast<float>(0.25 * size);
            for (int k = 0; k < 4; ++k)
                quarters[k] = {cell.at.chart, cell.at.u + ((k & 1) ? q : -q),
                               cell.at.v + ((k & 2) ? q : -q)};
            evaluateBatch(surface, quarters, quarterGeometry);
            for (int k = 0; k < 4; ++k)
                stack.push_back({quarters[k], quarterGeometry[k], cell.depth + 1});
            continue;
        }
        if (glm::dot(p, camera.forward) <= camera.zNear) continue;
        float x, y;
        if (!camera.project(P, x, y) ||
            !(x >= 0.0f && y >= 0.0f && x <= camera.width && y <= camera.height))
            continue;
        if (closed && glm::dot(linear * g.Ng, p) >= 0.0f) continue;
        // Pixels per unit of u and of v; inverted, the chart units a pixel step spans (the
        // probe query's derivatives, surface_points.cpp), here in level-0 texels.
        const glm::dvec2 ju = screenDerivative(camera, ppu, p, linear * g.dPdu);
        const glm::dvec2 jv = screenDerivative(camera, ppu, p, linear * g.dPdv);
        const double det = ju.x * jv.y - ju.y * jv.x;
        if (!(std::fabs(det) > 1e-30) || hidden(world, camera.eye, P)) continue;
        out.covered += std::fabs(det) * cells.stride * size * size;
        // Level-0 texels a side along each chart axis.
        const auto chart = static_cast<size_t>(cell.at.chart);
        const double Ru = std::ldexp(double(d.resolution), -int(cells.shift.u[chart]));
        const double Rv = std::ldexp(double(d.resolution), -int(cells.shift.v[chart]));
        const double s = footprint / det;
        const double la = std::hypot(jv.y * Ru * s, ju.y * Rv * s),
                     lb = std::hypot(jv.x * Ru * s, ju.x * Rv * s);
        const double major = std::max(la, lb);
        double minor = std::min(la, lb);
        // The level the probe reads (probe_batch.h footprintOf): the minor axis, widened.
        if (probe.cap == AnisotropyCap::ShrinkMajor) {
            if (probe.levelAnisotropy > 0.0f)
                minor = std::max(minor, major / probe.levelAnisotropy);
        } else {
            minor = std::max(minor, major / probe.maxAnisotropy);
        }
        const double lod = std::clamp(std::log2(std::max(minor, 1e-30)), 0.0, double(maxLevel));
        // Levels l0 and l0 + 1, each read only where its weight is not 0 (prober.h's
        // narrowBlend: the coarser one's weight rises across levelBlend around the middle).
        const int l0 = static_cast<int>(lod);
        const double t = lod - l0, halfBlend = 0.5 * std::min(1.0f, probe.levelBlend);
        const int l1 = std::min(l0 + 1, maxLevel);
        const int level =
            l1 > l0 && (probe.levelBlend >= 1.0f ? t >= 1.0 : t >= 0.5 + halfBlend) ? l1 : l0;
        const int last =
            l1 > l0 && (probe.levelBlend >= 1.0f ? t > 0.0 : t > 0.5 - halfBlend) ? l1 : l0;
        out.finest = std::min(out.finest, level);
        // The tiles the cell's points read on each level: points two a tile side within the
        // cell (a tile is filled when any probe lands in it, and the cell's box would count
        // every tile it grazes), or the cell's area where it is many tiles wide.
        for (int l = level; l <= last; ++l) {
            // Tiles a chart side along u and v; at least one texel an axis.
            const double sideU = std::max(1.0, Ru / double(1 << l)) / tile;
            const double sideV = std::max(1.0, Rv / double(1 << l)) / tile;
            const double extentU = sideU * size, extentV = sideV * size;  // the cell's, in tiles
            if (extentU * extentV > 16.0) {
                out.tiles += std::max(extentU, 1.0) * std::max(extentV, 1.0) * cells.stride;
                continue;
            }
            const int mu = std::max(1, static_cast<int>(std::ceil(2.0 * extentU)));
            const int mv = std::max(1, static_cast<int>(std::ceil(2.0 * extentV)));
            const double u0 = cell.at.u - 0.5 * size, v0 = cell.at.v - 0.5 * size;
            for (int j = 0; j < mv; ++j)
                for (int i = 0; i < mu; ++i) {
                    const double u = u0 + (i + 0.5) * size / mu, v = v0 + (j + 0.5) * size / mv;
                    asked.insert(tileId(cell.at.chart, l, static_cast<int64_t>(u * sideU),
                                        static_cast<int64_t>(v * sideV)));
                }
        }
    }
    out.tiles += static_cast<double>(asked.size()) * cells.stride;
    return out;
}

}  // namespace

std::vector<MapDemand> estimateMapDemands(const SceneResources& resources,
                                          std::span<const size_t> objects,
                                          const MapDemandOptions& options) {
    const Scene& scene = resources.scene();
    const int width = options.width > 0 ? options.width : scene.settings.width;
    const int height = options.height > 0 ? options.height : scene.settings.height;
    const int spp =
        options.samplesPerPixel > 0 ? options.samplesPerPixel : scene.settings.samplesPerPixel;
    const double footprint = options.footprintScale / std::sqrt(static_cast<double>(spp));

    std::vector<MapDemand> demands(objects.size());
    std::vector<ChartCells> cells(objects.size());
    std::vector<int> maxLevels(objects.size(), 0), tiles(objects.size(), 1);
    for (size_t n = 0; n < objects.size(); ++n) {
        const SceneObject& obj = scene.objects[objects[n]];
        MapDemand& d = demands[n];
        const int cap = obj.shadermapResolution > 0 ? obj.shadermapResolution : (1 << 20);
        d.resolution = 1;
        while (d.resolution < cap && d.resolution < (1 << 20)) d.resolution *= 2;
        tiles[n] = std::min(options.tileSize, d.resolution);
        d.tileTexels = (tiles[n] + 2 * options.border) * (tiles[n] + 2 * options.border);
        while ((d.resolution >> maxLevels[n]) > 1) ++maxLevels[n];
        cells[n] = chartCells(*obj.surface, options.points);
        cells[n].shift = chartShifts(
            *obj.surface, options.chartAspect ? chartShiftRoom(d.resolution, tiles[n]) : 0);
        d.pinnedTiles = coarseLevelTiles(cells[n].shift, d.resolution, tiles[n],
                                         ShaderMapOptions{}.alwaysResidentLevels);
    }

    const int first = std::max(0, options.firstFrame);
    const int end = options.lastFrame >= 0 ? options.lastFrame : std::max(1, scene.frameCount());
    const int count = std::max(1, end - first);
    const int nFrames = std::clamp(options.frames, 1, count);
    std::unordered_set<uint64_t> asked;
    for (int f = 0; f < nFrames; ++f) {
        const int frame =
            first + (nFrames == 1
                         ? 0
                         : static_cast<int>(std::lround(double(f) * (count - 1) / (nFrames - 1))));
        const FrameState state = frameStateAt(resources, frame, width, height, spp);
        const WorldRayScene world(resources, state.objects);
        for (size_t n = 0; n < objects.size(); ++n) {
            const Surface& surface = *scene.objects[objects[n]].surface;
            const FrameDemand fd = frameDemand(
                surface, cells[n], demands[n], maxLevels[n], tiles[n], isClosed(surface), state,
                state.objects[objects[n]], world.scene(), footprint, options.probe, asked);
            MapDemand& d = demands[n];
            d.frames.push_back(frame);
            d.frameTiles.push_back(fd.covered > 0.0 ? fd.tiles : 0.0);
            if (fd.covered > 0.0 && fd.tiles > d.tiles) {
                d.tiles = fd.tiles;
                d.frame = frame;
                d.coveredPixels = fd.covered;
                d.finestLevel = fd.finest;
            }
        }
    }
    return demands;
}

}  // namespace mpshade
