#include "controller/multiphase_renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

namespace mpshade {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

MultiphaseRenderer::MultiphaseRenderer(const Scene& scene, const MultiphaseOptions& options)
    : scene_(scene),
      options_(options),
      resources_(scene, SceneResources::RayScenes::ForOcclusion),
      static_(scene, resources_, options.staticPhase),
      dynamic_(scene),
      cache_(options.mapMemoryBytes) {
    options_.dynamic.trace = options.trace;
    const size_t n = scene.objects.size();
    representations_.resize(n);
    kinds_.assign(n, Representation::Auto);
    longestEdge_.assign(n, 0.0f);
    framesSeen_.assign(n, {});
    reports_.resize(n);
    for (size_t i = 0; i < n; ++i) reports_[i].name = scene.objects[i].name;
    lastBuildSeconds_.assign(n, 0.0);
    staticInputs_.resize(n);
    for (size_t i = 0; i < n; ++i) staticInputs_[i] = StaticInputs(factored(i).staticPart);
    inputSpans_ = staticInputSpans(resources_, staticInputs_);
    builtInputs_.assign(n, {});
}

MultiphaseRenderer::~MultiphaseRenderer() = default;

const ObjectRepresentation* MultiphaseRenderer::representation(size_t object) const {
    return representations_[object].get();
}

const FactoredShader& MultiphaseRenderer::factored(size_t object) const {
    return static_.shading(object).factored;
}

float MultiphaseRenderer::inputsMoved(size_t object) {
    if (staticInputs_[object].empty()) return 0.0f;
    staticInputs_[object].read(frame_.uniforms[object], inputScratch_);
    return staticInputChange(builtInputs_[object], inputScratch_, inputSpans_[object]);
}

double MultiphaseRenderer::pauseFiller() {
    if (!filler_) return 0.0;
    const auto start = Clock::now();
    filler_->pause();
    return secondsSince(start);
}

void MultiphaseRenderer::resumeFiller() {
    if (filler_) filler_->resume(useStamp_);
}

void MultiphaseRenderer::discardStaticWork() {
    if (filler_) {
        filler_->pause();
        filler_->submit({});
    }
    for (auto& rep : representations_) rep.reset();
    kinds_.assign(kinds_.size(), Representation::Auto);
    longestEdge_.assign(longestEdge_.size(), 0.0f);
}

void MultiphaseRenderer::plan(int first, int last, const RenderOptions& options) {
    planFirst_ = first;
    layoutWidth_ = options.width > 0 ? options.width : scene_.settings.width;
    layoutHeight_ = options.height > 0 ? options.height : scene_.settings.height;
    for (std::vector<int>& seen : framesSeen_)
        seen.assign(static_cast<size_t>(std::max(0, last - first)), 0);
    const int w = options.width > 0 ? options.width : scene_.settings.width;
    const int h = options.height > 0 ? options.height : scene_.settings.height;
    for (int f = first; f < last; ++f) {
        const float t = scene_.frameTime(f);
        const CameraState camera = cameraAt(scene_, t, w, h);
        for (size_t i = 0; i < scene_.objects.size(); ++i) {
            const bool seen = objectInView(*scene_.objects[i].surface,
                                           objectAt(scene_.objects[i], t, camera), camera);
            framesSeen_[i][static_cast<size_t>(f - first)] =
                (f > first ? framesSeen_[i][static_cast<size_t>(f - first - 1)] : 0) +
                (seen ? 1 : 0);
        }
    }
}

ObjectCostInputs MultiphaseRenderer::costInputs(size_t i, int frame, const ObjectState& state,
                                                const CameraState& camera, int spp) const {
    const SceneObject& obj = scene_.objects[i];
    const ObjectShading& shading = static_.shading(i);
    const ObjectRepresentation* previous = representations_[i].get();
    const int tile =
        options_.staticPhase.shaderMap.tileSize + 2 * options_.staticPhase.shaderMap.border;
    ObjectCostInputs in;
    in.charts = chartCount(*obj.surface);
    // The 32 x 32 level is four 16 x 16 tiles, the five below one each.
    in.pinnedTiles = static_cast<double>(in.charts) * 9.0;
    in.pinnedBytes = in.pinnedTiles * tile * tile *
                     static_cast<double>(shading.factored.staticPart.channelOutputs.size()) *
                     sizeof(float);
    in.haveMap = previous && previous->map;
    in.pinnedUpFront = options_.staticPhase.shaderMap.fillPinnedUpFront;
    // The screen area: the object's bounding sphere, projected, within the screen.
    const Bounds3 b = surfaceBounds(*obj.surface);
    const float ppu = 0.5f * static_cast<float>(camera.height) / camera.tanHalfFovY;
    const float distance = std::max(glm::length(state.eye - b.center()), 1e-20f);
    const float radius = 0.5f * b.diagonal();
    const double projected =
        distance > radius ? 3.14159265 * std::pow(ppu * radius / distance, 2.0) : 1e30;
    in.coveredPixels = std::min(static_cast<double>(camera.width) * camera.height, projected);
    in.frames = std::max(1, framesSeenFrom(i, frame));
    in.combinedRuns = predictedCombinedRuns(i, frame, state);
    in.screenPixels = static_cast<double>(camera.width) * camera.height;
    in.channels = static_cast<int>(shading.factored.staticPart.channelOutputs.size());
    in.staticCostUnits = shading.factored.staticCost;
    in.recomputedCostUnits = shading.factored.recomputedStaticCost;
    in.originalCostUnits = shading.factored.originalCost;
    in.samplesPerPixel = spp;
    in.shadingRate = options_.dynamic.shadingRate;
    in.footprintScale = options_.dynamic.footprintScale;
    return in;
}

Representation MultiphaseRenderer::chooseKind(size_t i, int frame, const ObjectState& state,
                                              const CameraState& camera, int spp,
                                              ObjectCostInputs& in) {
    const SceneObject& obj = scene_.objects[i];
    Representation asked = options_.representation.value_or(obj.representation);
    in = costInputs(i, frame, state, camera, spp);
    if (asked == Representation::Facets)
        in.combinedFacets = static_.combinedFacets(i, state, camera);
    if (asked != Representation::Auto) {
        reports_[i].reason =
            options_.representation ? "forced by the renderer's options" : "the scene asks for it";
        std::string tooBig;
        if (asked == Representation::ShaderMap && !in.haveMap &&
            !shaderMapFits(in, tooBig, options_.costModel)) {
            reports_[i].reason += ", but " + tooBig + ": facets instead";
            return Representation::Facets;
        }
        return asked;
    }
    in.combinedFacets = static_.combinedFacets(i, state, camera);
    const RepresentationChoice choice = chooseRepresentation(in, options_.costModel);
    reports_[i].reason = choice.reason;
    return choice.kind;
}

bool MultiphaseRenderer::singlePhasePays(const std::vector<size_t>& stale,
                                         const std::vector<ObjectCostInputs>& staleInputs,
                                         const std::vector<uint8_t>& visible, int frame,
                                         bool leastCost) const {
    // Over the frames F the new static work would serve: multi-phase pays that work, then
    // every visible object's dynamic frames; single-phase pays the reference's frames for
    // every visible object, since a frame rendered single-phase builds nothing and the
    // next one meets the same choice.
    int served = 1;
    for (const ObjectCostInputs& in : staleInputs) served = std::max(served, in.frames);
    double multi = 0.0, single = 0.0;
    std::vector<int> staleAt(visible.size(), -1);
    for (size_t k = 0; k < stale.size(); ++k) staleAt[stale[k]] = static_cast<int>(k);
    for (size_t i = 0; i < visible.size(); ++i) {
        if (!visible[i]) continue;
        const int k = staleAt[i];
        ObjectCostInputs in =
            k >= 0 ? staleInputs[static_cast<size_t>(k)]
                   : costInputs(i, frame, frame_.objects[i], frame_.camera, frame_.spp);
        if (k < 0)
            in.combinedFacets = static_cast<double>(representations_[i]->mesh.facetCount());
        else if (leastCost)
            // Unsurveyed: facets at a quarter of the 20-50 per covered pixel the survey
            // usually finds.
            in.combinedFacets = 5.0 * in.coveredPixels;
        const RepresentationChoice c = chooseRepresentation(in, options_.costModel);
        const double frames = std::min(served, std::max(1, in.frames));
        const double facets =
            (k >= 0 ? c.facetsStaticSeconds : 0.0) + frames * c.facetsFrameSeconds;
        const double map = (k >= 0 ? c.mapStaticSeconds : 0.0) + frames * c.mapFrameSeconds;
        if (k >= 0 && leastCost)
            multi += std::min(facets, map);  // whichever representation is cheaper
        else
            multi += (k >= 0 ? kinds_[i] : representations_[i]->kind) == Representation::Facets
                         ? facets
                         : map;
        single += frames * c.singlePhaseFrameSeconds;
    }
    return single < multi;
}

int MultiphaseRenderer::predictedCombinedRuns(size_t object, int frame,
                                              const ObjectState& state) const {
    // Facets diced for the view at P/2 are diced again when the eye comes closer (their
    // projected edges grow) or leaves the range: count those events along the planned
    // frames that see the object.
    const std::vector<int>& seen = framesSeen_[object];
    if (seen.empty()) return 1;
    const SceneObject& obj = scene_.objects[object];
    const Bounds3 b = surfaceBounds(*obj.surface);
    const glm::vec3 center = b.center();
    const float radius = 0.5f * b.diagonal();
    auto distance = [&](const glm::vec3& eye) {
        return std::max(glm::length(eye - center) - radius, 1e-3f * radius);
    };
    float diced = distance(state.eye);
    glm::vec3 direction = glm::normalize(state.eye - center);
    int runs = 1;
    const int last = planFirst_ + static_cast<int>(seen.size());
    for (int f = std::max(frame + 1, planFirst_); f < last; ++f) {
        const size_t k = static_cast<size_t>(f - planFirst_);
        if (seen[k] == (k > 0 ? seen[k - 1] : 0)) continue;  // not seen in frame f
        const float t = scene_.frameTime(f);
        const CameraState camera = cameraAt(scene_, t, layoutWidth_, layoutHeight_);
        const glm::vec3 eye = objectAt(obj, t, camera).eye;
        const float d = distance(eye);
        const glm::vec3 dir = glm::normalize(eye - center);
        if (d < 0.95f * diced || d > obj.range.distanceFactor * diced ||
            glm::dot(dir, direction) < std::cos(glm::radians(obj.range.angle))) {
            ++runs;
            diced = d;
            direction = dir;
        }
    }
    return runs;
}

int MultiphaseRenderer::framesSeenFrom(size_t object, int frame) const {
    const std::vector<int>& seen = framesSeen_[object];
    if (seen.empty()) return scene_.frameCount() - frame;  // no plan: assume every frame
    const int first = std::clamp(frame - planFirst_, 0, static_cast<int>(seen.size()) - 1);
    return seen.back() - (first > 0 ? seen[static_cast<size_t>(first) - 1] : 0);
}

void MultiphaseRenderer::render(int frame, const RenderOptions& options, FrameStats& stats,
                                const ProgressFn& progress) {
    const auto start = Clock::now();
    stats = FrameStats{};
    frame_ =
        frameStateAt(resources_, frame, options.width, options.height, options.samplesPerPixel);
    frameStaticSeconds_.assign(scene_.objects.size(), 0.0);
    frameDynamic_.assign(scene_.objects.size(), ObjectFrameCost{});
    if (filler_) {
        // Held while this frame's static work runs; no probe runs now either, so the
        // storage of the tiles it dropped meanwhile is free again. The wait (at most the
        // tile under way) is the controller's time.
        stats.controllerSeconds += pauseFiller();
        const BackgroundTotals t = filler_->totals();
        stats.backgroundTilesFilled = t.tilesFilled - fillerTotals_.tilesFilled;
        stats.backgroundTilesEvicted = t.tilesEvicted - fillerTotals_.tilesEvicted;
        stats.backgroundSeconds = t.seconds - fillerTotals_.seconds;
        fillerTotals_ = t;
        for (const auto& pool : static_.tilePools().all()) pool->reclaim();
        for (const auto& rep : representations_)
            if (rep && rep->map) rep->map->reclaim();
    }
    const CameraState& camera = frame_.camera;
    if (!layout_ ||
        !layout_->matches(frame_.width, frame_.height, frame_.spp, options.seed, options.filter)) {
        // A few layouts are kept: a player switching samples per pixel (its quality
        // regulator) goes back and forth between two, and one costs 0.06-0.08 s to make at
        // 480x270.
        layout_ = nullptr;
        for (const auto& kept : layouts_)
            if (kept->matches(frame_.width, frame_.height, frame_.spp, options.seed,
                              options.filter))
                layout_ = kept;
        if (!layout_) {
            const ScopedSpan span(options_.trace, "sample layout", PhaseKind::Dynamic,
                                  SpanLevel::Phase, -1, frame);
            layout_ = std::make_shared<const SampleLayout>(frame_.width, frame_.height, frame_.spp,
                                                           options.seed, options.filter);
            if (layouts_.size() == 3) layouts_.erase(layouts_.begin());
            layouts_.push_back(layout_);
        }
    }
    DynamicOptions dynamicOptions = options_.dynamic;
    if (options_.shadingRate)
        dynamicOptions.shadingRate = *options_.shadingRate;
    else
        dynamicOptions.shadingRate = scene_.settings.shadingRate;
    options_.dynamic.shadingRate = dynamicOptions.shadingRate;

    // 1-2. Objects in view, and the static phase for those that need it.
    const auto triggersStart = Clock::now();
    const size_t n = scene_.objects.size();
    std::vector<uint8_t> visible(n, 0);
    std::vector<size_t> stale;
    for (size_t i = 0; i < n; ++i) {
        const ObjectState& state = frame_.objects[i];
        visible[i] = objectInView(*scene_.objects[i].surface, state, camera) ? 1 : 0;
        if (!visible[i]) continue;
        const ObjectRepresentation* rep = representations_[i].get();
        const glm::vec3 forward =
            glm::normalize(glm::vec3(state.worldToObject * glm::vec4(camera.forward, 0.0f)));
        StaticRunDue due;
        due.object = static_cast<uint32_t>(i);
        if (!rep) {
            stats.staticRunsDue.push_back(due);
            stale.push_back(i);
            continue;
        }
        const ObjectRepresentation::RangeCheck range = rep->checkRange(state.eye, forward);
        if (range.fiducial != ObjectRepresentation::RangeCheck::None) {
            due.cause = range.fiducial == ObjectRepresentation::RangeCheck::ViewDirection
                            ? StaticRunDue::ViewDirection
                        : range.fiducial == ObjectRepresentation::RangeCheck::Distance
                            ? StaticRunDue::Distance
                            : StaticRunDue::AngleAround;
            due.measured = range.measured;
            due.threshold = range.threshold;
        } else if (inputsMoved(i) > options_.staticInputTolerance) {
            due.cause = StaticRunDue::StaticInput;
            due.measured = inputsMoved(i);
            due.threshold = options_.staticInputTolerance;
        } else if (rep->imageHeight != camera.height) {
            due.cause = StaticRunDue::ImageSize;
            due.measured = static_cast<float>(camera.height);
            due.threshold = static_cast<float>(rep->imageHeight);
        } else if (rep->kind == Representation::Facets && longestEdge_[i] > rep->maxEdgePixels) {
            due.cause = StaticRunDue::FacetsTooLong;
            due.measured = longestEdge_[i];
            due.threshold = rep->maxEdgePixels;
        } else {
            continue;
        }
        stats.staticRunsDue.push_back(due);
        stale.push_back(i);
    }
    // A frame budget: what was never built is built; what is due again is rebuilt, cheapest
    // first, only while its last run, and half as much again (a re-dice of a nearer view
    // makes more facets), fits the time left after the dynamic phase (as long as the last
    // frame's) and the twentieth kept for the end of the frame; the others are drawn from
    // their last representation.
    const bool budgeted = options_.frameBudgetSeconds > 0.0;
    if (budgeted && !stale.empty()) {
        std::vector<size_t> due, again;
        for (size_t i : stale) (representations_[i] ? again : due).push_back(i);
        std::sort(again.begin(), again.end(),
                  [&](size_t a, size_t b) { return lastBuildSeconds_[a] < lastBuildSeconds_[b]; });
        double left =
            0.95 * options_.frameBudgetSeconds - secondsSince(start) - lastDynamicSeconds_;
        for (size_t i : again) {
            if (1.5 * lastBuildSeconds_[i] <= left) {
                due.push_back(i);
                left -= 1.5 * lastBuildSeconds_[i];
            } else {
                ++stats.rebuildsDeferred;
                for (StaticRunDue& d : stats.staticRunsDue)
                    if (d.object == i) d.deferred = true;
            }
        }
        std::sort(due.begin(), due.end());
        stale = due;
    }
    stats.controllerSeconds += secondsSince(triggersStart);
    const auto staticStart = Clock::now();
    // First a check that needs no dicing survey: with every stale object at the least its
    // representations could cost, does single-phase still win? (A cut every frame then
    // costs the reference's frame plus this check.) Else the representations are chosen
    // and the check is made again with their estimates.
    std::vector<ObjectCostInputs> staleInputs(stale.size());
    singlePhaseFrame_ = false;
    if (options_.singlePhaseFrames && !budgeted && !stale.empty()) {
        for (size_t k = 0; k < stale.size(); ++k)
            staleInputs[k] =
                costInputs(stale[k], frame, frame_.objects[stale[k]], camera, frame_.spp);
        singlePhaseFrame_ = singlePhasePays(stale, staleInputs, visible, frame, true);
    }
    if (!singlePhaseFrame_) {
        std::vector<Representation> previousKinds = kinds_;
        std::vector<std::string> previousReasons(stale.size());
        for (size_t k = 0; k < stale.size(); ++k) {
            const size_t i = stale[k];
            previousReasons[k] = reports_[i].reason;
            kinds_[i] = chooseKind(i, frame, frame_.objects[i], camera, frame_.spp, staleInputs[k]);
        }
        singlePhaseFrame_ = options_.singlePhaseFrames && !budgeted && !stale.empty() &&
                            singlePhasePays(stale, staleInputs, visible, frame, false);
        if (singlePhaseFrame_) {
            // Nothing is built: the objects stay as they were; the next frame decides again.
            kinds_ = previousKinds;
            for (size_t k = 0; k < stale.size(); ++k)
                reports_[stale[k]].reason = previousReasons[k];
        }
    }
    if (singlePhaseFrame_) {
        if (!reference_) reference_ = std::make_unique<ReferenceRenderer>(scene_);
        const ScopedSpan span(options_.trace, "single-phase frame", PhaseKind::Reference,
                              SpanLevel::Phase, -1, frame);
        singlePhaseSamples_ = reference_->renderSamples(frame, options, stats, progress);
        stats.singlePhase = true;
        stats.wallSeconds = secondsSince(start);
        return;
    }
    std::vector<StaticCosts> costs(stale.size());
    tbb::parallel_for(size_t{0}, stale.size(), [&](size_t k) {
        const size_t i = stale[k];
        const ScopedSpan task(options_.trace, "build", PhaseKind::Static, SpanLevel::Task,
                              static_cast<int64_t>(i), frame);
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
        frameStaticSeconds_[stale[k]] += costs[k].seconds;
        lastBuildSeconds_[stale[k]] = costs[k].seconds;
        staticInputs_[stale[k]].read(frame_.uniforms[stale[k]], builtInputs_[stale[k]]);
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
    if (options_.trace && !stale.empty())
        options_.trace->span("static phase", PhaseKind::Static, SpanLevel::Phase, staticStart,
                             Clock::now(), -1, frame);
    if (progress) progress(1, 4);

    // 3. The dynamic phase; lacking tiles filled between shading passes.
    std::vector<const ObjectRepresentation*> drawn(n, nullptr);
    for (size_t i = 0; i < n; ++i)
        if (visible[i]) drawn[i] = representations_[i].get();
    ++useStamp_;
    for (const auto& rep : representations_)
        if (rep && rep->map) rep->map->setUseStamp(useStamp_);
    if (filler_) {
        // Queued tiles of maps a static run has just replaced are of no use now.
        if (stats.staticRuns > 0)
            filler_->retain([&](const BackgroundJob& job) {
                const ObjectRepresentation* rep = representations_[job.object].get();
                return rep && rep->map == job.map;
            });
        if (options_.backgroundDuringFrames) filler_->resume(useStamp_);
    }
    dynamic_.begin(frame_, drawn, layout_, dynamicOptions);
    if (progress) progress(2, 4);
    StaticCosts fills;
    FillTiming fillTiming;
    fillTiming.trace = options_.trace;
    fillTiming.frame = frame;
    lacking_.clear();
    if (budgeted) {
        // Once, with fallbacks; the tiles lacked are filled after the resolve, in the time
        // left (fillWithinBudget).
        lacking_ = dynamic_.shade(true);
        stats.tilesRequested += lacking_.size();
        drawn_ = drawn;
    }
    if (!prefetched_.empty()) settlePrefetched(stats);
    for (int pass = 0; !budgeted; ++pass) {
        const bool last = pass >= 6;  // a safety net: each pass fills what the last lacked
        const std::vector<TileRequest> lacking = dynamic_.shade(last);
        stats.tilesRequested += lacking.size();
        if (lacking.empty() || last) break;
        const auto fillStart = Clock::now();
        // Room for the new tiles first, so the maps' storage never outgrows the budget.
        size_t incoming = 0;
        for (const TileRequest& r : lacking) incoming += drawn[r.object]->map->tileBytes();
        keepMapsInBudget(incoming, stats);
        static_.fill(lacking, drawn, fills, &fillTiming);
        stats.fillSeconds += secondsSince(fillStart);
        if (options_.trace)
            options_.trace->span("fill", PhaseKind::Static, SpanLevel::Phase, fillStart,
                                 Clock::now(), -1, frame);
        for (const TileRequest& r : lacking) ++reports_[r.object].staticCosts.tilesFilled;
    }
    stats.staticSeconds += stats.fillSeconds;
    stats.staticInstructions += fills.instructions;
    stats.tilesFilled += fills.tilesFilled;
    stats.tilesFromChildren += fills.tilesFromChildren;
    stats.texelsFilled += fills.texelsFilled;
    if (progress) progress(3, 4);

    for (size_t i = 0; i < fillTiming.objectSeconds.size(); ++i) {
        frameStaticSeconds_[i] += fillTiming.objectSeconds[i];
        reports_[i].staticCosts.seconds += fillTiming.objectSeconds[i];
        reports_[i].staticCosts.instructions += fillTiming.objectInstructions[i];
    }
    const DynamicFrameStats& d = dynamic_.stats();
    const std::vector<ObjectFrameCost>& objectCosts = dynamic_.objectCosts();
    frameDynamic_ = objectCosts;
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
    recordResidency(stats);
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

void MultiphaseRenderer::recordResidency(FrameStats& stats) const {
    stats.residentTiles = stats.residentBytes = stats.residentPinnedBytes = 0;
    for (const auto& pool : static_.tilePools().all()) {
        stats.residentTiles += pool->tilesHeld();
        stats.residentBytes += pool->bytesHeld();
        stats.residentPinnedBytes += pool->pinnedBytesHeld();
    }
}

bool MultiphaseRenderer::keepMapsInBudget(size_t incoming, FrameStats& stats) {
    const auto start = Clock::now();
    const bool fits = cache_.makeRoom(static_.tilePools(), incoming, useStamp_, stats.tilesEvicted);
    stats.controllerSeconds += secondsSince(start);
    return fits;
}

void MultiphaseRenderer::setFrameBudget(double seconds) {
    options_.frameBudgetSeconds = seconds;
    if (seconds > 0.0) cache_.reserve(static_.tilePools());
}

Image MultiphaseRenderer::renderFrame(int frame, const RenderOptions& options, FrameStats& stats,
                                      const ProgressFn& progress) {
    Image image;
    renderFrame(frame, options, stats, image, progress);
    return image;
}

void MultiphaseRenderer::renderFrame(int frame, const RenderOptions& options, FrameStats& stats,
                                     Image& image, const ProgressFn& progress) {
    const auto start = Clock::now();
    const ScopedSpan span(options_.trace, "frame", PhaseKind::Frame, SpanLevel::Phase, -1, frame);
    render(frame, options, stats, progress);
    if (singlePhaseFrame_) {
        singlePhaseSamples_.layout->resolve(singlePhaseSamples_.rgba.data(), nullptr, image);
        stats.wallSeconds = secondsSince(start);
        return;
    }
    dynamic_.resolve(image);
    stats.resolveSeconds = dynamic_.stats().resolveSeconds;
    if (options_.frameBudgetSeconds > 0.0) {
        const DynamicFrameStats& d = dynamic_.stats();
        lastDynamicSeconds_ = d.warpSeconds + d.rasterSeconds + d.shadeSeconds + d.resolveSeconds;
        fillWithinBudget(start, stats);
    }
    stats.wallSeconds = secondsSince(start);
    if (options_.frameBudgetSeconds > 0.0) {
        stats.budgetSeconds = options_.frameBudgetSeconds;
        stats.deadlineMet = stats.wallSeconds <= options_.frameBudgetSeconds;
    }
    if (progress) progress(4, 4);
}

SampleBuffer MultiphaseRenderer::renderSamples(int frame, const RenderOptions& options,
                                               FrameStats& stats, const ProgressFn& progress) {
    const auto start = Clock::now();
    render(frame, options, stats, progress);
    if (options_.frameBudgetSeconds > 0.0 && !singlePhaseFrame_) {
        fillWithinBudget(start, stats);
        stats.budgetSeconds = options_.frameBudgetSeconds;
        stats.deadlineMet = secondsSince(start) <= options_.frameBudgetSeconds;
    }
    return singlePhaseFrame_ ? singlePhaseSamples_ : dynamic_.samples();
}

}  // namespace mpshade
