// representation_planner.h -- which representation an object gets at a static run, and
// whether a frame's due static work pays for itself at all (design.md: "each object gets
// the representation that costs least for the frames it appears in"; "never slower than
// not using mpshade"). The estimates are representation_choice.h's; this feeds them what
// the plan knows: the frames from now on that see the object (Fearing 1996's look-ahead
// over the planned frames), how often the combined facets would be diced again along
// them, and the object's screen area now.
#pragma once

#include <optional>
#include <span>
#include <vector>

#include "controller/object_slot.h"
#include "phases/dynamic_phase.h"
#include "phases/representation_choice.h"
#include "phases/static_phase.h"

namespace mpshade {

// The mean, over the pixels a surface covers, of its shader-map footprints' elongation: major
// over minor axis, 1 / |cos| of the view ray against the normal, up to `levelAnisotropy`
// (the probe's ProbeOptions::levelAnisotropy: a footprint past it reads the level of
// major / levelAnisotropy, and its fills stop growing). It says how many times a facing
// surface's texels a map of it fills per covered pixel. Sampled in object space, a grid on
// each of up to 64 charts (16 x 16 on a single chart), each sample weighed by the pixels it
// covers (area times |cos| over squared distance); samples outside the image are left out.
// 1 when none is inside. The grazing floor (examples/hard) measures 12 and a render of it
// fills 40 texels a covered pixel; the vase's floor measures 3.3 and its scene fills 20: an
// overestimate near the horizon, on the side of the reference renderer.
double footprintElongation(const Surface& surface, const ObjectState& state,
                           const CameraState& camera, float levelAnisotropy);

class RepresentationPlanner {
  public:
    // scene, statics: not owned, must outlive the planner. forced: every object's
    // representation, overriding the scene's (unset: the scene's).
    RepresentationPlanner(const Scene& scene, const StaticPhase& statics,
                          const RepresentationCostModel& model,
                          std::optional<Representation> forced);

    // The frames that will be asked for, [first, last) at width x height pixels (as
    // rendered: RenderOptions::resolved). Without a plan every frame of the scene is assumed to see
    // every object.
    void plan(int first, int last, int width, int height);

    // The estimate's inputs that need no dicing survey (combinedFacets is left 0).
    // `dynamic`: the shading rate and footprint scale the frames are rendered with.
    ObjectCostInputs costInputs(size_t object, const ObjectSlot& slot, int frame,
                                const ObjectState& state, const CameraState& camera, int spp,
                                const DynamicOptions& dynamic) const;
    // The representation object `object` gets if built now for this view; its inputs go
    // to `in`, and the reason to slot.report.reason.
    Representation choose(size_t object, ObjectSlot& slot, int frame, const ObjectState& state,
                          const CameraState& camera, int spp, const DynamicOptions& dynamic,
                          ObjectCostInputs& in) const;
    // Whether the due static work (objects `due`, with their inputs `dueInputs` and their
    // chosen kinds in slots[i].kind) costs more, with the frames it serves, than rendering
    // those frames single-phase. Over those frames multi-phase pays that work and every
    // visible object's dynamic frames; single-phase pays the reference's frames for every
    // visible object, since a frame rendered single-phase builds nothing and the next one
    // meets the same choice. leastCost: the due objects are not surveyed yet; each is taken
    // at the least either representation could cost.
    bool singlePhasePays(std::span<const size_t> due, std::span<const ObjectCostInputs> dueInputs,
                         std::span<const uint8_t> visible, std::span<const ObjectSlot> slots,
                         const FrameState& frame, int index, const DynamicOptions& dynamic,
                         bool leastCost) const;

  private:
    int framesSeenFrom(size_t object, int frame) const;
    int predictedCombinedRuns(size_t object, int frame, const ObjectState& state) const;

    const Scene& scene_;
    const StaticPhase& statics_;
    RepresentationCostModel model_;
    std::optional<Representation> forced_;
    // Per object, over the planned frames from first_: how many of the frames up to each
    // see it (a running count; empty without a plan).
    std::vector<std::vector<int>> framesSeen_;
    int first_ = 0;
    int width_ = 0, height_ = 0;  // the planned image size
};

}  // namespace mpshade
