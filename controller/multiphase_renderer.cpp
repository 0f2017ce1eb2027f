#include "controller/multiphase_renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <tuple>
#include <utility>

#include <tbb/parallel_for.h>

#include "controller/static_run_triggers.h"
#include "controller/view_lookahead.h"
#include "scene/scene_state.h"

namespace mpshade {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

// What one frame does, decided before anything is built or shaded.
struct MultiphaseRenderer::FramePlan {
    int frame = 0;
    bool budgeted = false;                    // a frame budget (playback): nothing waits for tiles
    std::vector<uint8_t> visible;             // per object: in view this frame
    std::vector<size_t> due;                  // objects whose static phase runs this frame
    std::vector<ObjectCostInputs> dueInputs;  // their cost estimates' inputs
    std::vector<const ObjectRepresentation*> drawn;  // per object, null: not drawn
};

MultiphaseRenderer::MultiphaseRenderer(const Scene& scene, const MultiphaseOptions& options)
    : scene_(scene),
      options_(options),
      resources_(scene, SceneResources::RayScenes::ForOcclusion),
      static_(scene, resources_, options.staticPhase),
      dynamic_(scene),
      cache_(options.mapMemoryBytes),
      tiles_(static_, cache_),
      planner_(scene, static_, options.costModel, options.representation),
      slots_(scene.objects.size()),
      refiner_(options.refine),
      planLast_(scene.frameCount()) {
    options_.dynamic.trace = options.trace;
    std::vector<StaticInputs> inputs(slots_.size());
    for (size_t i = 0; i < slots_.size(); ++i) {
        slots_[i].report.name = scene.objects[i].name;
        inputs[i] = StaticInputs(factored(i).staticPart);
    }
    std::vector<std::vector<float>> spans = staticInputSpans(resources_, inputs);
    for (size_t i = 0; i < slots_.size(); ++i) {
        slots_[i].staticInputs = std::move(inputs[i]);
        slots_[i].inputSpans = std::move(spans[i]);
    }
}

MultiphaseRenderer::~MultiphaseRenderer() = default;

const ObjectRepresentation* MultiphaseRenderer::representation(size_t object) const {
    return slots_[object].representation.get();
}

const FactoredShader& MultiphaseRenderer::factored(size_t object) const {
    return static_.shading(object).factored;
}

ShadingCostImage MultiphaseRenderer::lastFrameShadingCost() const {
    if (singlePhaseFrame_ || !dynamic_.layout()) return {};
    std::vector<float> costPerPoint(slots_.size(), 0.0f);
    for (size_t i = 0; i < slots_.size(); ++i) {
        const ObjectRepresentation* rep = slots_[i].representation.get();
        if (!rep) continue;
        const FactoredShader& f = factored(i);
        costPerPoint[i] = static_cast<float>(rep->kind == Representation::Direct ? f.originalCost
                                                                                 : f.dynamicCost);
    }
    return shadingCostImage(*dynamic_.layout(), dynamic_.visibility(), dynamic_.pointOptions(),
                            costPerPoint);
}

std::vector<const ObjectRepresentation*> MultiphaseRenderer::representations() const {
    std::vector<const ObjectRepresentation*> out(slots_.size(), nullptr);
    for (size_t i = 0; i < slots_.size(); ++i) out[i] = slots_[i].representation.get();
    return out;
}

DynamicOptions MultiphaseRenderer::dynamicOptionsFor(const RenderOptions& options) const {
    DynamicOptions o = options_.dynamic;
    o.shadingRate =
        options.shadingRate.value_or(options_.shadingRate.value_or(scene_.settings.shadingRate));
    if (options.footprintScale > 0.0f) o.footprintScale = options.footprintScale;
    if (!options.reuseStillView) o.reuseBytes = 0;
    o.keepFirstView = o.keepFirstView && !viewAnimated();
    if (options_.footprints.enabled) o.objectFootprint = footprintScales();
    return o;
}

// A camera or a placement animated: the first frame's view does not hold still.
bool MultiphaseRenderer::viewAnimated() const {
    bool animated =
        scene_.camera.eye.varies() || scene_.camera.target.varies() || scene_.camera.up.varies();
    for (const SceneObject& object : scene_.objects)
        animated = animated || object.transform.animated();
    return animated;
}

void MultiphaseRenderer::discardStaticWork() {
    if (builder_) builder_->cancel();
    if (filler_) {
        filler_->pause();
        filler_->submit({});
    }
    for (ObjectSlot& slot : slots_) {
        slot.representation.reset();
        slot.kind = Representation::Auto;
        slot.longestEdge = 0.0f;
    }
}

void MultiphaseRenderer::plan(int first, int last, const RenderOptions& options) {
    const RenderOptions o = options.resolved(scene_.settings);
    planner_.plan(first, last, o.width, o.height);
    planLast_ = last;
}

void MultiphaseRenderer::setFrameBudget(double seconds) {
    options_.frameBudgetSeconds = seconds;
    if (seconds > 0.0) cache_.reserve(static_.tilePools());
}

// A frame, at constant quality or within a frame budget, is these steps in order:
//   beginFrame          the frame's state and sample layout; the background filler held.
//   adoptRebuilt        within a budget: representations the background builder finished
//                       replace those the frames drew meanwhile.
//   planFrame           the objects in view, and of them those whose static phase is due,
//                       with why (static_run_triggers.h). Nothing is done for an object
//                       until a frame sees it.
//   deferRebuilds       within a budget: rebuilds to the background builder, or only as
//                       they fit the frame's time.
//   rendersSinglePhase  representations chosen for the due objects
//                       (representation_planner.h); if that work would not pay for itself
//                       over the frames it serves, the reference renderer draws the frame
//                       and nothing is built.
//   buildDue            the static phase of the due objects, in parallel.
//   shadeAndFill        the dynamic phase; at constant quality, the tiles its probes found missing
//                       are filled (tile_filler.h) and only the bands that missed them are
//                       shaded again, so no sample reads a coarser level than its footprint
//                       asks and the image does not depend on what earlier frames filled.
//   calibrateFootprints at constant quality, objects shown well for the first time have
//                       their footprints chosen from measured error, for the frames after
//                       (footprint_calibration.h); this frame's samples are left as shaded.
//   recordFrame         what the frame drew and cost, per object (object_slot.h) and in all.
// renderFrame() then resolves pixels and, within a budget, fills the missing tiles in the
// time left (frame_budget.cpp). Playback's look-ahead and prefetching are frame_budget.cpp
// and tile_prefetch.cpp.
void MultiphaseRenderer::render(int frame, const RenderOptions& options, FrameStats& stats,
                                const ProgressFn& progress) {
    const auto start = Clock::now();
    beginFrame(frame, options, stats);
    const auto triggersStart = Clock::now();
    if (builder_) adoptRebuilt(frame, stats);
    FramePlan plan = planFrame(frame, stats);
    if (plan.budgeted) deferRebuilds(plan, start, stats);
    stats.controllerSeconds += secondsSince(triggersStart);
    const auto staticStart = Clock::now();
    singlePhaseFrame_ = rendersSinglePhase(plan);
    if (singlePhaseFrame_) {
        if (!reference_) reference_ = std::make_unique<ReferenceRenderer>(scene_);
        const ScopedSpan span(options_.trace, "single-phase frame", PhaseKind::Reference,
                              SpanLevel::Phase, -1, frame);
        singlePhaseSamples_ = reference_->renderSamples(frame, options, stats, progress);
        stats.singlePhase = true;
        stats.wallSeconds = secondsSince(start);
        return;
    }
    buildDue(plan, stats);
    stats.staticWork.seconds = secondsSince(staticStart);
    if (options_.trace && !plan.due.empty())
        options_.trace->span("static phase", PhaseKind::Static, SpanLevel::Phase, staticStart,
                             Clock::now(), -1, frame);
    if (progress) progress(1, 4);
    shadeAndFill(plan, stats, progress);
    calibrateFootprints(plan.frame, plan.drawn, stats);
    recordFrame(plan, stats);
    stats.wallSeconds = secondsSince(start);
}

// The frame's state, its costs reset, the background filler held and its work counted,
// and its sample layout.
void MultiphaseRenderer::beginFrame(int frame, const RenderOptions& options, FrameStats& stats) {
    stats = FrameStats{};
    compareLastFrameWithReference();
    const RenderOptions o = options.resolved(scene_.settings);
    frame_ = frameStateAt(resources_, frame, o.width, o.height, o.samplesPerPixel);
    for (ObjectSlot& slot : slots_) {
        slot.frameStaticSeconds = 0.0;
        slot.frameDynamic = ObjectFrameCost{};
        slot.builtThisFrame = false;
        slot.frameTilesFilled = 0;
    }
    if (filler_) {
        // Held while this frame's static work runs; no probe runs now either, so the
        // storage of the tiles it dropped meanwhile is free again. The wait (at most the
        // tile under way) is the controller's time.
        const auto held = Clock::now();
        filler_->pause();
        stats.controllerSeconds += secondsSince(held);
        const BackgroundTotals t = filler_->totals();
        stats.background = {t.tilesFilled - fillerTotals_.tilesFilled,
                            t.tilesEvicted - fillerTotals_.tilesEvicted,
                            t.seconds - fillerTotals_.seconds};
        fillerTotals_ = t;
        for (const auto& pool : static_.tilePools().all()) pool->reclaim();
        for (const ObjectSlot& slot : slots_)
            if (slot.representation && slot.representation->map)
                slot.representation->map->reclaim();
    }
    const auto asked = Clock::now();
    bool made = false;
    layout_ =
        layouts_.get(frame_.width, frame_.height, frame_.spp, options.seed, options.filter, &made);
    if (made && options_.trace)
        options_.trace->span("sample layout", PhaseKind::Dynamic, SpanLevel::Phase, asked,
                             Clock::now(), -1, frame);
    dynamicOptions_ = dynamicOptionsFor(options);
}

// The last frame's work for each object drawn from a stored representation, against what
// the reference would have spent on it, both in the cost model's terms
// (static_run_triggers.h): objects the scene leaves to auto.
void MultiphaseRenderer::compareLastFrameWithReference() {
    if (!options_.directWhenSlower || options_.representation || frame_.spp == 0) return;
    const RepresentationCostModel& m = options_.costModel;
    const ShaderMapOptions& maps = static_.options().shaderMap;
    const double texelsPerTile = std::pow(maps.tileSize + 2.0 * maps.border, 2.0);
    const double samplesPerPoint =
        frame_.spp / shadingPointsPerPixel(dynamicOptions_.shadingRate, frame_.spp);
    for (size_t i = 0; i < slots_.size(); ++i) {
        const ObjectSlot& slot = slots_[i];
        if (scene_.objects[i].representation != Representation::Auto || !slot.representation)
            continue;
        const FactoredShader& f = factored(i);
        const double points = static_cast<double>(slot.frameDynamic.shadingPoints);
        const bool map = slot.representation->kind == Representation::ShaderMap;
        const double stored = 1e-9 * (static_cast<double>(slot.frameTilesFilled) * texelsPerTile *
                                          staticRunNs(m, f.staticCost) +
                                      points * (map ? m.mapPointNs : m.vertexPointNs));
        const double reference =
            1e-9 * points * samplesPerPoint * referenceNsPerSample(m, f.originalCost);
        compareWithReference(slots_[i], stored, reference, static_.shading(i).directAllowed);
    }
}

// 1-2. The objects in view, and of them those whose static phase is due, with why.
MultiphaseRenderer::FramePlan MultiphaseRenderer::planFrame(int frame, FrameStats& stats) {
    FramePlan plan;
    plan.frame = frame;
    plan.budgeted = options_.frameBudgetSeconds > 0.0;
    plan.visible.assign(slots_.size(), 0);
    for (size_t i = 0; i < slots_.size(); ++i) {
        const ObjectState& state = frame_.objects[i];
        if (!objectInView(*scene_.objects[i].surface, state, frame_.camera)) continue;
        plan.visible[i] = 1;
        const std::optional<StaticRunDue> due =
            staticRunDue(static_cast<uint32_t>(i), slots_[i], state, frame_.camera,
                         frame_.uniforms[i], options_.staticInputTolerance, inputScratch_);
        if (!due) continue;
        stats.staticWork.due.push_back(*due);
        plan.due.push_back(i);
    }
    return plan;
}

// The representations the background builder finished since the last frame replace those
// the frames drew meanwhile, as if built now (recordBuild), their costs the builder's.
void MultiphaseRenderer::adoptRebuilt(int frame, FrameStats& stats) {
    for (RebuiltObject& done : builder_->takeFinished()) {
        const size_t i = done.job.object;
        const ScopedSpan span(options_.trace, "take up rebuilt", PhaseKind::Static, SpanLevel::Task,
                              static_cast<int64_t>(i), frame);
        ObjectSlot& slot = slots_[i];
        std::unique_ptr<ObjectRepresentation> old = std::move(slot.representation);
        slot.representation = std::move(done.representation);
        // Its share of a map dropped here, so that a map is only ever freed on this thread.
        if (old) {
            old->map.reset();
            builder_->discard(std::move(old));
        }
        slot.builtThisFrame = true;
        recordBuild(i, done.job.kind, done.costs, done.job.ownUniforms());
        ++stats.background.rebuilds;
        stats.background.rebuildSeconds += done.costs.seconds;
    }
}

// A frame budget. A rebuild for a new view that makes no shader map goes to the background
// builder (MultiphaseOptions::backgroundRebuilds), and one already there waits for it; the
// others run only as they fit the time left after the dynamic phase (as long as the last
// frame's) and the twentieth kept for the end of the frame.
void MultiphaseRenderer::deferRebuilds(FramePlan& plan, Clock::time_point start,
                                       FrameStats& stats) {
    if (plan.due.empty()) return;
    if (options_.backgroundRebuilds) sendRebuildsToBackground(plan, stats);
    if (plan.due.empty()) return;
    const double left =
        0.95 * options_.frameBudgetSeconds - secondsSince(start) - lastDynamicSeconds_;
    plan.due =
        admitRebuilds(plan.due, slots_, left, stats.staticWork.due, stats.budget.rebuildsDeferred);
}

// Takes out of plan.due the rebuilds for a new view that make no shader map, queued for the
// background builder at this frame's view, and those it has under way already: each drawn
// from its last representation meanwhile.
void MultiphaseRenderer::sendRebuildsToBackground(FramePlan& plan, FrameStats& stats) {
    std::vector<size_t> inFrame;
    for (const size_t i : plan.due) {
        ObjectSlot& slot = slots_[i];
        StaticRunDue* due = nullptr;
        for (StaticRunDue& d : stats.staticWork.due)
            if (d.object == i) due = &d;
        const bool forView =
            due &&
            (due->cause == StaticRunDue::ViewDirection || due->cause == StaticRunDue::Distance ||
             due->cause == StaticRunDue::AngleAround || due->cause == StaticRunDue::FacetsTooLong);
        const bool takes = forView && slot.representation &&
                           !static_.buildMakesMap(i, slot.kind, slot.representation.get());
        if (!takes && !(builder_ && builder_->pending(i))) {
            inFrame.push_back(i);
            continue;
        }
        if (takes) {
            if (!builder_)
                builder_ =
                    std::make_unique<BackgroundBuilder>(static_, options_.backgroundIdlePriority);
            RebuildJob job;
            job.object = i;
            job.kind = slot.kind;
            BuildView view =
                buildView(i, frame_.index, frame_.objects[i], frame_.camera, frame_.uniforms[i]);
            job.state = view.state;
            job.camera = view.camera;
            job.uniforms = view.uniforms;
            job.params.assign(job.uniforms.params.begin(), job.uniforms.params.end());
            job.lights.assign(job.uniforms.lights.begin(), job.uniforms.lights.end());
            job.previous = slot.representation.get();
            builder_->submit(std::move(job));
        }
        if (due) due->deferred = true;
        ++stats.budget.rebuildsDeferred;
        ++stats.budget.rebuildsInBackground;
    }
    plan.due = std::move(inFrame);
}

// 2b. Whether the due static work would not pay for itself, so the frame is rendered by the
// reference renderer and nothing is built. First a check that needs no dicing survey: with
// every due object at the least its representations could cost, does single-phase still
// win? (A cut every frame then costs the reference's frame plus this check.) Else the
// representations are chosen and the check is made again with their estimates.
bool MultiphaseRenderer::rendersSinglePhase(FramePlan& plan) {
    const bool mayRenderSingle = options_.singlePhaseFrames && !plan.budgeted && !plan.due.empty();
    plan.dueInputs.assign(plan.due.size(), ObjectCostInputs{});
    if (mayRenderSingle) {
        for (size_t k = 0; k < plan.due.size(); ++k) {
            const size_t i = plan.due[k];
            plan.dueInputs[k] = planner_.costInputs(i, slots_[i], plan.frame, frame_.objects[i],
                                                    frame_.camera, frame_.spp, dynamicOptions_);
        }
        if (planner_.singlePhasePays(plan.due, plan.dueInputs, plan.visible, slots_, frame_,
                                     plan.frame, dynamicOptions_, true))
            return true;
    }
    std::vector<Representation> previousKinds(plan.due.size());
    std::vector<std::string> previousReasons(plan.due.size());
    for (size_t k = 0; k < plan.due.size(); ++k) {
        ObjectSlot& slot = slots_[plan.due[k]];
        previousKinds[k] = slot.kind;
        previousReasons[k] = slot.report.reason;
        slot.kind = planner_.choose(plan.due[k], slot, plan.frame, frame_.objects[plan.due[k]],
                                    frame_.camera, frame_.spp, dynamicOptions_, plan.dueInputs[k]);
    }
    if (!mayRenderSingle ||
        !planner_.singlePhasePays(plan.due, plan.dueInputs, plan.visible, slots_, frame_,
                                  plan.frame, dynamicOptions_, false))
        return false;
    // Nothing is built: the objects stay as they were; the next frame decides again.
    for (size_t k = 0; k < plan.due.size(); ++k) {
        slots_[plan.due[k]].kind = previousKinds[k];
        slots_[plan.due[k]].report.reason = previousReasons[k];
    }
    return true;
}

// The static phase of every due object, in parallel over objects.
void MultiphaseRenderer::buildDue(const FramePlan& plan, FrameStats& stats) {
    std::vector<StaticCosts> costs(plan.due.size());
    tbb::parallel_for(size_t{0}, plan.due.size(), [&](size_t k) {
        const size_t i = plan.due[k];
        const ScopedSpan task(options_.trace, "build", PhaseKind::Static, SpanLevel::Task,
                              static_cast<int64_t>(i), plan.frame);
        ObjectSlot& slot = slots_[i];
        const BuildView view =
            buildView(i, plan.frame, frame_.objects[i], frame_.camera, frame_.uniforms[i]);
        slot.representation = static_.build(i, slot.kind, view.state, view.camera, view.uniforms,
                                            slot.representation.get(), costs[k]);
        slot.builtThisFrame = true;
    });
    for (size_t k = 0; k < plan.due.size(); ++k) {
        const size_t i = plan.due[k];
        recordBuild(i, slots_[i].kind, costs[k], frame_.uniforms[i]);
        slots_[i].frameStaticSeconds += costs[k].seconds;
        stats.staticWork.work += costs[k];
    }
}

// The view object i's static phase is built for at frame `frame`, where the object's state
// is `present`, the camera `camera` and its uniforms `uniforms`: that view, or one ahead
// whose range holds it (view_lookahead.h). The same whichever path builds it (in the frame,
// in the background, ahead of a locked frame rate's frames), so a frame does not depend on
// which did. The object stands where it stands at `frame` over the frames considered, so
// its placement, and what its static part reads, are that frame's: of the uniforms only the
// eye is the chosen view's.
MultiphaseRenderer::BuildView MultiphaseRenderer::buildView(size_t i, int frame,
                                                            const ObjectState& present,
                                                            const CameraState& camera,
                                                            const ShadingUniforms& uniforms) const {
    BuildView view{present, camera, uniforms};
    // Views up to twice the look-ahead: a view ahead is worth as many frames as its range
    // holds, before it and after.
    const int ahead = options_.viewLookahead;
    const int last = std::min(frame + 2 * ahead, planLast_ - 1);
    if (ahead <= 0 || last <= frame || !viewAnimated()) return view;
    std::vector<ObjectViewpoint> views = {
        {present.eye, viewForward(present, camera), present.objectToWorld}};
    std::vector<std::pair<ObjectState, CameraState>> states = {{present, camera}};
    for (int f = frame + 1; f <= last; ++f) {
        const float t = scene_.frameTime(f);
        const CameraState c = cameraAt(scene_, t, camera.width, camera.height);
        const ObjectState state = objectAt(scene_.objects[i], t, c);
        views.push_back({state.eye, viewForward(state, c), state.objectToWorld});
        states.emplace_back(state, c);
    }
    const ObjectSlot& slot = slots_[i];
    const glm::vec3 center = slot.representation
                                 ? slot.representation->center
                                 : surfaceBounds(*scene_.objects[i].surface).center();
    std::tie(view.state, view.camera) =
        states[holdingView(views, static_cast<size_t>(ahead), center, scene_.objects[i].range)];
    view.uniforms.eye = view.state.eye;
    return view;
}

void MultiphaseRenderer::recordBuild(size_t i, Representation kind, const StaticCosts& costs,
                                     const ShadingUniforms& uniforms) {
    ObjectSlot& slot = slots_[i];
    slot.kind = kind;
    slot.longestEdge = 0.0f;
    slot.rebuildSeconds = costs.seconds - costs.keptMapSeconds;
    slot.staticInputs.read(uniforms, slot.builtInputs);
    ObjectReport& r = slot.report;
    r.kind = kind;
    ++r.staticRuns;
    r.staticCosts += costs;
}

// 3. The dynamic phase. At constant quality the tiles its probes found missing are filled between
// shading passes, and only the bands that missed them are shaded again; within a budget it
// shades once, with fallbacks, and the missing tiles are filled after the resolve in the
// time left (fillWithinBudget).
void MultiphaseRenderer::shadeAndFill(FramePlan& plan, FrameStats& stats,
                                      const ProgressFn& progress) {
    plan.drawn.assign(slots_.size(), nullptr);
    for (size_t i = 0; i < slots_.size(); ++i)
        if (plan.visible[i]) plan.drawn[i] = slots_[i].representation.get();
    ++useStamp_;
    for (const ObjectSlot& slot : slots_)
        if (slot.representation && slot.representation->map)
            slot.representation->map->setUseStamp(useStamp_);
    if (filler_) {
        // Queued tiles of maps a static run has just replaced are of no use now.
        if (stats.staticWork.work.runs > 0)
            filler_->retain([&](const BackgroundJob& job) {
                const ObjectRepresentation* rep = slots_[job.object].representation.get();
                return rep && rep->map == job.map;
            });
        if (options_.backgroundDuringFrames) filler_->resume(useStamp_);
    }
    dynamic_.begin(frame_, plan.drawn, layout_, dynamicOptions_);
    if (progress) progress(2, 4);
    missing_.clear();
    if (plan.budgeted) {
        missing_ = dynamic_.shade(true);
        stats.tiles.missing += missing_.size();
        drawn_ = plan.drawn;
    }
    if (!prefetched_.empty()) settlePrefetched(stats);
    TileFillResult fills;
    for (int pass = 0; !plan.budgeted; ++pass) {
        const bool last = pass >= 6;  // a safety net: each pass fills what the last found missing
        const std::vector<TileRequest> missing = dynamic_.shade(last);
        stats.tiles.missing += missing.size();
        if (missing.empty() || last) break;
        tiles_.fill(missing, plan.drawn, fillLimits(CacheRoom::EvictAndExceed, plan.frame), fills);
    }
    countFills(fills, stats);
    if (progress) progress(3, 4);
}

FillLimits MultiphaseRenderer::fillLimits(CacheRoom room, int frame) const {
    FillLimits limits;
    limits.room = room;
    limits.useStamp = useStamp_;
    limits.trace = options_.trace;
    limits.frame = frame;
    return limits;
}

void MultiphaseRenderer::countFills(const TileFillResult& fills, FrameStats& stats) {
    stats.staticWork.fillSeconds += fills.seconds;
    stats.staticWork.seconds += fills.seconds;
    stats.staticWork.work += fills.costs;
    stats.controllerSeconds += fills.roomSeconds;
    stats.tiles.evicted += fills.evicted;
    stats.budget.fillsStopped += fills.stopped;
    for (size_t i = 0; i < fills.objectTiles.size(); ++i) {
        const uint64_t loaded =
            i < fills.timing.objectTilesLoaded.size() ? fills.timing.objectTilesLoaded[i] : 0;
        slots_[i].report.staticCosts.tilesFilled += fills.objectTiles[i] - loaded;
        slots_[i].report.staticCosts.tilesLoaded += loaded;
        slots_[i].frameTilesFilled += fills.objectTiles[i];
    }
    for (size_t i = 0; i < fills.timing.objectSeconds.size(); ++i) {
        slots_[i].frameStaticSeconds += fills.timing.objectSeconds[i];
        slots_[i].report.staticCosts.seconds += fills.timing.objectSeconds[i];
        slots_[i].report.staticCosts.instructions += fills.timing.objectInstructions[i];
    }
}

// What the frame drew and cost, per object and in all.
void MultiphaseRenderer::recordFrame(const FramePlan& plan, FrameStats& stats) {
    const std::vector<ObjectFrameCost>& objectCosts = dynamic_.objectCosts();
    for (size_t i = 0; i < slots_.size(); ++i) {
        ObjectSlot& slot = slots_[i];
        slot.frameDynamic = objectCosts[i];
        const ObjectRepresentation* drawn = plan.drawn[i];
        if (!drawn) continue;
        slot.longestEdge = objectCosts[i].longestEdgePixels;
        ObjectReport& r = slot.report;
        r.longestEdgePixels = slot.longestEdge;
        ++r.framesDrawn;
        r.facets = drawn->mesh.facetCount();
        r.facetBytes = drawn->bytes();
        if (drawn->map) {
            r.residentTiles = drawn->map->residentTiles();
            r.mapBytes = drawn->map->bytes();
        }
        ++stats.objectsDrawn;
    }
    recordResidency(static_.tilePools(), stats);
    stats.dynamic = dynamic_.stats();
    stats.shadedPoints = stats.dynamic.shadingPoints;
    stats.shaderInstructions = stats.dynamic.instructions;
    stats.nonFiniteSamples = stats.dynamic.nonFinite;
    stats.index = plan.frame;
    stats.time = frame_.time;
    stats.samples = static_cast<uint64_t>(frame_.width) * frame_.height * frame_.spp;
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
    stats.dynamic.resolveSeconds = dynamic_.stats().resolveSeconds;
    if (options_.frameBudgetSeconds > 0.0) {
        lastDynamicSeconds_ = dynamic_.stats().seconds();
        if (options_.refine.enabled) refineWithinBudget(start, image, stats);
        fillWithinBudget(start, stats);
    }
    stats.wallSeconds = secondsSince(start);
    if (options_.frameBudgetSeconds > 0.0) {
        stats.budget.seconds = options_.frameBudgetSeconds;
        stats.budget.deadlineMet = stats.wallSeconds <= options_.frameBudgetSeconds;
    }
    if (progress) progress(4, 4);
}

SampleBuffer MultiphaseRenderer::renderSamples(int frame, const RenderOptions& options,
                                               FrameStats& stats, const ProgressFn& progress) {
    const auto start = Clock::now();
    render(frame, options, stats, progress);
    if (options_.frameBudgetSeconds > 0.0 && !singlePhaseFrame_) {
        fillWithinBudget(start, stats);
        stats.budget.seconds = options_.frameBudgetSeconds;
        stats.budget.deadlineMet = secondsSince(start) <= options_.frameBudgetSeconds;
    }
    return singlePhaseFrame_ ? singlePhaseSamples_ : dynamic_.samples();
}

}  // namespace mpshade
