#include "phases/multiphase_renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <string>

#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>

namespace mpshade {
namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

// Whether any of the object's bounding sphere lies inside the view frustum.
bool inView(const Surface& surface, const ObjectState& state, const CameraState& camera) {
    const Bounds3 b = surfaceBounds(surface);
    const glm::vec3 c = glm::vec3(state.objectToWorld * glm::vec4(b.center(), 1.0f)) - camera.eye;
    const float r = 0.5f * b.diagonal() * state.scale;
    const float depth = glm::dot(c, camera.forward);
    if (depth < camera.zNear - r || depth > camera.zFar + r) return false;
    const float tx = camera.tanHalfFovY * camera.aspect, ty = camera.tanHalfFovY;
    const glm::vec3 planes[4] = {glm::normalize(camera.right - tx * camera.forward),
                                 glm::normalize(-camera.right - tx * camera.forward),
                                 glm::normalize(camera.up - ty * camera.forward),
                                 glm::normalize(-camera.up - ty * camera.forward)};
    for (const glm::vec3& n : planes)
        if (glm::dot(c, n) > r) return false;
    return true;
}

// The surface's area (object units^2), from |dPdu x dPdv| on an 8 x 8 grid per chart.
double surfaceArea(const Surface& surface) {
    constexpr int kGrid = 8;
    std::vector<ChartPoint> points;
    const int charts = chartCount(surface);
    for (int chart = 0; chart < charts; ++chart)
        for (int j = 0; j < kGrid; ++j)
            for (int i = 0; i < kGrid; ++i)
                points.push_back({chart, (i + 0.5f) / kGrid, (j + 0.5f) / kGrid});
    std::vector<SurfaceSample> samples(points.size());
    evaluateBatch(surface, points, samples);
    double area = 0.0;
    for (const SurfaceSample& s : samples)
        area += glm::length(glm::cross(s.dPdu, s.dPdv)) / (kGrid * kGrid);
    return area;
}

}  // namespace

MultiphaseRenderer::MultiphaseRenderer(const Scene& scene, const MultiphaseOptions& options)
    : scene_(scene),
      options_(options),
      resources_(scene),
      static_(scene, resources_,
              [&] {
                  StaticPhaseOptions o = options.staticPhase;
                  if (const char* e = std::getenv("MPX_SS")) o.shaderMap.supersampleLimit = std::stoi(e);
                  if (const char* e = std::getenv("MPX_TILE")) o.shaderMap.tileSize = std::stoi(e);
                  if (std::getenv("MPX_HALF")) o.shaderMap.halfPrecision = true;
                  return o;
              }()),
      dynamic_(scene) {
    const size_t n = scene.objects.size();
    representations_.resize(n);
    kinds_.assign(n, Representation::Auto);
    longestEdge_.assign(n, 0.0f);
    framesSeen_.assign(n, scene.frameCount());
    surfaceArea_.assign(n, -1.0);
    reports_.resize(n);
    for (size_t i = 0; i < n; ++i) reports_[i].name = scene.objects[i].name;
}

MultiphaseRenderer::~MultiphaseRenderer() = default;

const ObjectRepresentation* MultiphaseRenderer::representation(size_t object) const {
    return representations_[object].get();
}

const FactoredShader& MultiphaseRenderer::factored(size_t object) const {
    return static_.shading(object).factored;
}

void MultiphaseRenderer::plan(int first, int last, const RenderOptions& options) {
    std::fill(framesSeen_.begin(), framesSeen_.end(), 0);
    for (int f = first; f < last; ++f) {
        const float t = scene_.frameTime(f);
        const int w = options.width > 0 ? options.width : scene_.settings.width;
        const int h = options.height > 0 ? options.height : scene_.settings.height;
        const CameraState camera = cameraAt(scene_, t, w, h);
        for (size_t i = 0; i < scene_.objects.size(); ++i)
            if (inView(*scene_.objects[i].surface, objectAt(scene_.objects[i], t, camera), camera))
                ++framesSeen_[i];
    }
}

Representation MultiphaseRenderer::chooseKind(size_t i, const ObjectState& state,
                                              const CameraState& camera, int spp) {
    const SceneObject& obj = scene_.objects[i];
    Representation asked = options_.representation.value_or(obj.representation);
    if (asked != Representation::Auto) {
        reports_[i].reason = options_.representation ? "forced by the renderer's options"
                                                     : "the scene asks for it";
        return asked;
    }
    if (surfaceArea_[i] < 0.0) surfaceArea_[i] = surfaceArea(*obj.surface);
    const ObjectShading& shading = static_.shading(i);
    ObjectCostInputs in;
    const float ppu = 0.5f * static_cast<float>(camera.height) / camera.tanHalfFovY;
    const Bounds3 b = surfaceBounds(*obj.surface);
    const float distance = std::max(glm::length(state.eye - b.center()) - 0.5f * b.diagonal(),
                                    camera.zNear / state.scale);
    const double scale = static_cast<double>(ppu) / std::max(distance, 0.25f * glm::length(state.eye - b.center()));
    in.surfacePixels = surfaceArea_[i] * scale * scale;
    in.coveredPixels = std::min(static_cast<double>(camera.width) * camera.height,
                                in.surfacePixels * (shading.closed ? 0.25 : 0.5));
    in.closed = shading.closed;
    in.charts = chartCount(*obj.surface);
    in.frames = std::max(1, framesSeen_[i]);
    in.staticCostUnits = shading.factored.staticCost;
    const int k = std::max(1, options_.staticPhase.shaderMap.supersampleLimit);
    in.supersamples = k * k;
    in.samplesPerPixel = spp;
    in.shadingRate = options_.dynamic.shadingRate;
    const int tile = options_.staticPhase.shaderMap.tileSize +
                     2 * options_.staticPhase.shaderMap.border;
    in.pinnedBytes = static_cast<double>(in.charts) * 9.0 * tile * tile *
                     shading.factored.staticPart.channelOutputs.size() * sizeof(float);
    const RepresentationChoice choice = chooseRepresentation(in, options_.costModel);
    reports_[i].reason = choice.reason;
    return choice.kind;
}

void MultiphaseRenderer::render(int frame, const RenderOptions& options, FrameStats& stats,
                                const ProgressFn& progress) {
    const auto start = Clock::now();
    stats = FrameStats{};
    frame_ = frameStateAt(resources_, frame, options.width, options.height,
                          options.samplesPerPixel);
    const CameraState& camera = frame_.camera;
    if (!layout_ || !layout_->matches(frame_.width, frame_.height, frame_.spp, options.seed,
                                      options.filter))
        layout_ = std::make_shared<const SampleLayout>(frame_.width, frame_.height, frame_.spp,
                                                       options.seed, options.filter);
    DynamicOptions dynamicOptions = options_.dynamic;
    if (const char* e = std::getenv("MPX_FOOT")) dynamicOptions.footprintScale = std::stof(e);
    if (const char* e = std::getenv("MPX_ANISO")) dynamicOptions.probe.maxAnisotropy = std::stof(e);
    if (const char* e = std::getenv("MPX_BLEND")) dynamicOptions.probe.levelBlend = std::stof(e);
    if (const char* e = std::getenv("MPX_FILTER")) dynamicOptions.probe.filter = static_cast<ProbeFilter>(std::stoi(e));
    if (options_.shadingRate)
        dynamicOptions.shadingRate = *options_.shadingRate;
    else
        dynamicOptions.shadingRate = scene_.settings.shadingRate;
    options_.dynamic.shadingRate = dynamicOptions.shadingRate;

    // 1-2. Objects in view, and the static phase for those that need it.
    const size_t n = scene_.objects.size();
    std::vector<uint8_t> visible(n, 0);
    std::vector<size_t> stale;
    for (size_t i = 0; i < n; ++i) {
        const ObjectState& state = frame_.objects[i];
        visible[i] = inView(*scene_.objects[i].surface, state, camera) ? 1 : 0;
        if (!visible[i]) continue;
        const ObjectRepresentation* rep = representations_[i].get();
        const glm::vec3 forward =
            glm::normalize(glm::vec3(state.worldToObject * glm::vec4(camera.forward, 0.0f)));
        const bool tooCoarse = rep && rep->kind == Representation::Facets &&
                               longestEdge_[i] > rep->maxEdgePixels;
        if (!rep || !rep->inRange(state.eye, forward) || rep->imageHeight != camera.height ||
            tooCoarse)
            stale.push_back(i);
    }
    const auto staticStart = Clock::now();
    for (size_t i : stale)
        if (kinds_[i] == Representation::Auto)
            kinds_[i] = chooseKind(i, frame_.objects[i], camera, frame_.spp);
    std::vector<StaticCosts> costs(stale.size());
    tbb::parallel_for(size_t{0}, stale.size(), [&](size_t k) {
        const size_t i = stale[k];
        representations_[i] =
            static_.build(i, kinds_[i], frame_.objects[i], camera, frame_.uniforms[i],
                          representations_[i].get(), costs[k]);
        longestEdge_[i] = 0.0f;
    });
    for (size_t k = 0; k < stale.size(); ++k) {
        ObjectReport& r = reports_[stale[k]];
        r.kind = kinds_[stale[k]];
        ++r.staticRuns;
        r.staticCosts.runs += costs[k].runs;
        r.staticCosts.seconds += costs[k].seconds;
        r.staticCosts.instructions += costs[k].instructions;
        r.staticCosts.programRuns += costs[k].programRuns;
        r.staticCosts.tilesFilled += costs[k].tilesFilled;
        stats.staticInstructions += costs[k].instructions;
        stats.tilesFilled += costs[k].tilesFilled;
        stats.tilesFromChildren += costs[k].tilesFromChildren;
        stats.texelsFilled += costs[k].texelsFilled;
    }
    stats.staticRuns = static_cast<int>(stale.size());
    stats.staticSeconds = secondsSince(staticStart);
    if (progress) progress(1, 4);

    // 3. The dynamic phase; lacking tiles filled between shading passes.
    std::vector<const ObjectRepresentation*> drawn(n, nullptr);
    for (size_t i = 0; i < n; ++i)
        if (visible[i]) drawn[i] = representations_[i].get();
    dynamic_.begin(frame_, drawn, layout_, dynamicOptions);
    if (progress) progress(2, 4);
    StaticCosts fills;
    for (int pass = 0;; ++pass) {
        const bool last = pass >= 6;  // a safety net: each pass fills what the last lacked
        const std::vector<TileRequest> lacking = dynamic_.shade(last);
        stats.tilesRequested += lacking.size();
        if (lacking.empty() || last) break;
        const auto fillStart = Clock::now();
        static_.fill(lacking, drawn, fills);
        stats.fillSeconds += secondsSince(fillStart);
        for (const TileRequest& r : lacking) ++reports_[r.object].staticCosts.tilesFilled;
    }
    stats.staticSeconds += stats.fillSeconds;
    stats.staticInstructions += fills.instructions;
    stats.tilesFilled += fills.tilesFilled;
    stats.tilesFromChildren += fills.tilesFromChildren;
    stats.texelsFilled += fills.texelsFilled;
    if (progress) progress(3, 4);

    const DynamicFrameStats& d = dynamic_.stats();
    const std::vector<ObjectFrameCost>& objectCosts = dynamic_.objectCosts();
    for (size_t i = 0; i < n; ++i) {
        if (!drawn[i]) continue;
        longestEdge_[i] = objectCosts[i].longestEdgePixels;
        ObjectReport& r = reports_[i];
        r.longestEdgePixels = longestEdge_[i];
        ++r.framesDrawn;
        r.facets = drawn[i]->mesh.facetCount();
        r.facetBytes = drawn[i]->bytes();
        if (drawn[i]->map) {
            r.residentTiles = drawn[i]->map->residentTiles();
            r.mapBytes = drawn[i]->map->bytes();
        }
        ++stats.objectsDrawn;
    }
    for (size_t i = 0; i < n; ++i)
        if (representations_[i] && representations_[i]->map) {
            stats.residentTiles += representations_[i]->map->residentTiles();
            stats.residentBytes += representations_[i]->map->bytes();
        }
    stats.warpSeconds = d.warpSeconds;
    stats.rasterSeconds = d.rasterSeconds;
    stats.shadeSeconds = d.shadeSeconds;
    stats.facets = d.facets;
    stats.verticesWarped = d.verticesWarped;
    stats.facetBytes = d.facetBytes;
    stats.facetsRasterized = d.raster.facetsBinned;
    stats.fragments = d.raster.fragments;
    stats.shadedPoints = d.shadingPoints;
    stats.shaderInstructions = d.instructions;
    stats.nonFiniteSamples = d.nonFinite;
    stats.probes = d.probes;
    stats.probeFallbacks = d.probeFallbacks;
    stats.shadePasses = d.shadePasses;
    stats.index = frame;
    stats.time = frame_.time;
    stats.samples = static_cast<uint64_t>(frame_.width) * frame_.height * frame_.spp;
    stats.wallSeconds = secondsSince(start);
}

Image MultiphaseRenderer::renderFrame(int frame, const RenderOptions& options, FrameStats& stats,
                                      const ProgressFn& progress) {
    const auto start = Clock::now();
    render(frame, options, stats, progress);
    Image image;
    dynamic_.resolve(image);
    stats.resolveSeconds = dynamic_.stats().resolveSeconds;
    stats.wallSeconds = secondsSince(start);
    if (progress) progress(4, 4);
    return image;
}

SampleBuffer MultiphaseRenderer::renderSamples(int frame, const RenderOptions& options,
                                               FrameStats& stats, const ProgressFn& progress) {
    render(frame, options, stats, progress);
    return dynamic_.samples();
}

}  // namespace mpshade
