// multiphase_renderer.h -- the controller's frame pipeline (patent FIG. 2, controller 240):
// what drives the static phase (phases/static_phase.h) and the dynamic phase
// (phases/dynamic_phase.h) frame by frame, at constant quality as `mpshade render` uses it,
// or within a frame budget as playback (playback.h) uses it. A frame is a short list of
// named steps over a FramePlan; multiphase_renderer.cpp lists them above render().
#pragma once

#include <chrono>
#include <memory>
#include <span>
#include <vector>

#include "controller/background_builder.h"
#include "controller/background_filler.h"
#include "controller/multiphase_options.h"
#include "controller/object_slot.h"
#include "controller/prefetch_ledger.h"
#include "controller/representation_planner.h"
#include "controller/tile_cache.h"
#include "controller/tile_filler.h"
#include "controller/tile_refiner.h"
#include "phases/dynamic_phase.h"
#include "phases/reference_renderer.h"
#include "phases/sample_layout_cache.h"
#include "phases/shading_cost_image.h"

namespace mpshade {

class MultiphaseRenderer : public Renderer {
  public:
    MultiphaseRenderer(const Scene& scene, const MultiphaseOptions& options = {});
    ~MultiphaseRenderer();

    // Tells the renderer which frames will be asked for ([first, last), in order), so
    // auto can weigh each object's costs over the frames that see it. Optional: without
    // it every frame of the scene is assumed.
    void plan(int first, int last, const RenderOptions& options);

    // Renders frame `frame`, running the static phase first for objects that need it, at
    // the options' quality (RenderOptions::shadingRate and footprintScale).
    using Renderer::renderFrame;
    void renderFrame(int frame, const RenderOptions& options, FrameStats& stats, Image& image,
                     const ProgressFn& progress = {}) override;
    SampleBuffer renderSamples(int frame, const RenderOptions& options, FrameStats& stats,
                               const ProgressFn& progress = {}) override;

    // Drops every object's representation and shader-map tiles, as a camera cut to an
    // unrelated view leaves nothing to reuse: the next frame runs every static phase it
    // needs again (`mpshade eval` times its worst case this way). The factored shaders and
    // ray scenes, fixed for the whole render, stay.
    void discardStaticWork();

    // The current representation of object i (null before a frame has seen it).
    const ObjectRepresentation* representation(size_t object) const;
    const FactoredShader& factored(size_t object) const;
    // Per pixel, the shading points the last frame's dynamic phase made and their cost in
    // opCost units: a drawn object's dynamic part per point, or its whole shader where it
    // is drawn direct (phases/shading_cost_image.h). Before any frame, or when the last
    // was rendered single-phase, empty (width 0). Points shaded again by the refinement
    // (MultiphaseOptions::refine) are not in it: the frame's own pass is.
    ShadingCostImage lastFrameShadingCost() const;
    // With MultiphaseOptions::refine on and a frame budget: the steps the frames that follow
    // refine their tiles to, better and better (tile_refiner.h); none: no refinement.
    void setRefineSteps(std::vector<RefineStep> steps) { refineSteps_ = std::move(steps); }
    // Sets MultiphaseOptions::frameBudgetSeconds for the frames that follow (0: constant
    // quality), as playback does after rendering its first frame at constant quality.
    void setFrameBudget(double seconds);
    // Looks ahead (Fearing 1996's prediction, patent col. 11): objects not built yet that
    // frames (frame, frame + frames] will see are built now, each for the view of the first
    // of those frames that sees it, nearest first, while 1.5 times the estimated cost of the next
    // fits in `seconds`. Returns the seconds spent; `built` counts the objects built.
    double buildAhead(int frame, int frames, const RenderOptions& options, double seconds,
                      int& built);
    // Prefetching in a frame's slack (claims 10 and 11; predictions: tile_predictor.h).
    // The tiles next to those the last frame found missing (the 8 around, same level), not
    // resident.
    std::vector<TileRequest> adjacentTiles() const;
    // Fills those of `tiles` not resident, in order, while the time spent stays within
    // `seconds` and the cache has room left (a guess never evicts a tile); counts them in
    // stats.prefetch.filled. Returns the seconds spent.
    double prefetch(std::span<const TileRequest> tiles, double seconds, FrameStats& stats);
    const ObjectReport& report(size_t object) const { return slots_[object].report; }
    // Tiles queued for the background filler and not filled yet (0 without one).
    size_t backgroundQueued() const { return filler_ ? filler_->queued() : 0; }
    // Whether the background filler can do nothing more before the next frame (true
    // without one): background_filler.h.
    bool backgroundSettled() const { return !filler_ || filler_->settled(); }
    // Whether object's rebuild is with the background builder (queued, under way, or done
    // and not yet taken up by a frame).
    bool rebuildingInBackground(size_t object) const {
        return builder_ && builder_->pending(object);
    }
    // Waits until the background builder has nothing queued or under way (tests).
    void waitForBackgroundRebuilds() {
        if (builder_) builder_->waitIdle();
    }
    size_t objectCount() const { return slots_.size(); }
    // Per object, what the last frame cost it: ObjectSlot::frameStaticSeconds and
    // frameDynamic.
    const ObjectSlot& slot(size_t object) const { return slots_[object]; }
    const Scene& scene() const { return scene_; }
    // The frame states' source (ray scenes for occlusion included), fixed for the render.
    const SceneResources& resources() const { return resources_; }
    // The static phase (its objects' shading, their maps' precision checks).
    const StaticPhase& statics() const { return static_; }
    // The dynamic phase's options for a frame rendered with `options`: its shading rate
    // and footprint scale where it sets them, else MultiphaseOptions', else the scene's
    // shading rate.
    DynamicOptions dynamicOptionsFor(const RenderOptions& options) const;

  private:
    struct FramePlan;
    // The steps of a frame, in order (render()).
    void beginFrame(int frame, const RenderOptions& options, FrameStats& stats);
    void adoptRebuilt(int frame, FrameStats& stats);
    FramePlan planFrame(int frame, FrameStats& stats);
    void deferRebuilds(FramePlan& plan, std::chrono::steady_clock::time_point start,
                       FrameStats& stats);
    void sendRebuildsToBackground(FramePlan& plan, FrameStats& stats);
    bool rendersSinglePhase(FramePlan& plan);
    void buildDue(const FramePlan& plan, FrameStats& stats);
    void shadeAndFill(FramePlan& plan, FrameStats& stats, const ProgressFn& progress);
    void calibrateFootprints(int frame, std::span<const ObjectRepresentation* const> drawn,
                             FrameStats& stats);
    bool viewAnimated() const;  // the camera or an object's placement animated
    // Per object, its footprint multiplier (ObjectSlot::footprintScale); empty if all are 1.
    std::vector<float> footprintScales() const;
    void recordFrame(const FramePlan& plan, FrameStats& stats);
    void compareLastFrameWithReference();
    void render(int frame, const RenderOptions& options, FrameStats& stats,
                const ProgressFn& progress);

    // What object i's static phase is built for at a frame (multiphase_renderer.cpp).
    struct BuildView {
        ObjectState state;
        CameraState camera;
        ShadingUniforms uniforms;
    };
    BuildView buildView(size_t i, int frame, const ObjectState& present, const CameraState& camera,
                        const ShadingUniforms& uniforms) const;
    // Records one static run of object i (its slot, its report, the inputs it read).
    void recordBuild(size_t i, Representation kind, const StaticCosts& costs,
                     const ShadingUniforms& uniforms);
    // Adds what a fill did to the frame's stats and to each object's costs.
    void countFills(const TileFillResult& fills, FrameStats& stats);
    FillLimits fillLimits(CacheRoom room, int frame) const;  // the cache's, this frame's
    // With a frame budget: fills this frame's missing tiles (missing_) until the budget,
    // counted from `start`, is spent; queues what is left for the background filler.
    void fillWithinBudget(std::chrono::steady_clock::time_point start, FrameStats& stats);
    // With a frame budget and MultiphaseOptions::refine on: the frame just resolved into
    // `image` refined by tile (tile_refiner.h) until RefineOptions::until of the budget.
    void refineWithinBudget(std::chrono::steady_clock::time_point start, Image& image,
                            FrameStats& stats);
    void queueForBackground(size_t from);
    void settlePrefetched(FrameStats& stats);  // prefetch_ledger.h
    std::vector<const ObjectRepresentation*> representations() const;

    const Scene& scene_;
    MultiphaseOptions options_;
    SceneResources resources_;
    StaticPhase static_;
    DynamicPhase dynamic_;
    TileCache cache_;
    TileFiller tiles_;
    RepresentationPlanner planner_;
    std::vector<ObjectSlot> slots_;
    std::shared_ptr<const SampleLayout> layout_;  // the frame's
    SampleLayoutCache layouts_;
    FrameState frame_;
    DynamicOptions dynamicOptions_;                 // the frame's (dynamicOptionsFor)
    uint32_t useStamp_ = 0;                         // frames rendered: the maps' recency stamp
    std::unique_ptr<ReferenceRenderer> reference_;  // made at the first single-phase frame
    bool singlePhaseFrame_ = false;                 // the last frame was: its samples
    SampleBuffer singlePhaseSamples_;
    std::vector<float> inputScratch_;
    // With a frame budget: the frame's missing tiles and what drew them; the last frame's
    // missing tiles (for adjacentTiles); its dynamic phase (warp to resolve), seconds.
    std::vector<TileRequest> missing_, lastMissing_;
    std::vector<const ObjectRepresentation*> drawn_;
    double lastDynamicSeconds_ = 0.0;
    PrefetchLedger prefetched_;  // the tiles prefetched and not yet read
    TileRefiner refiner_;
    std::vector<RefineStep> refineSteps_;
    int planLast_;  // the end of the frames planned (plan()); the scene's last frame by default
    // The background filler (made at the first frame that defers tiles), and its totals at
    // the last frame. Last: destroyed (its worker joined) before anything it uses.
    BackgroundTotals fillerTotals_;
    std::unique_ptr<BackgroundFiller> filler_;
    // The background builder (made at the first rebuild it takes); destroyed first, its
    // worker joined before the representations it lends from and the static phase go.
    std::unique_ptr<BackgroundBuilder> builder_;
};

}  // namespace mpshade
