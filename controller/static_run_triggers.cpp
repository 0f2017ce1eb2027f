#include "controller/static_run_triggers.h"

#include <algorithm>

#include "scene/scene_state.h"

namespace mpshade {

std::optional<StaticRunDue> staticRunDue(uint32_t object, const ObjectSlot& slot,
                                         const ObjectState& state, const CameraState& camera,
                                         const ShadingUniforms& uniforms, float inputTolerance,
                                         std::vector<float>& scratch) {
    StaticRunDue due;
    due.object = object;
    const ObjectRepresentation* rep = slot.representation.get();
    if (!rep) return due;  // first seen
    if (slot.goesDirect && rep->kind != Representation::Direct) {
        due.cause = StaticRunDue::SlowerThanReference;
        due.measured = slot.measuredMs;
        due.threshold = slot.referenceMs;
        return due;
    }
    const ObjectRepresentation::RangeCheck range =
        rep->checkRange(state.eye, viewForward(state, camera));
    float inputsMoved = 0.0f;
    if (range.fiducial == ObjectRepresentation::RangeCheck::None && !slot.staticInputs.empty()) {
        slot.staticInputs.read(uniforms, scratch);
        inputsMoved = staticInputChange(slot.builtInputs, scratch, slot.inputSpans);
    }
    if (range.fiducial != ObjectRepresentation::RangeCheck::None) {
        due.cause = range.fiducial == ObjectRepresentation::RangeCheck::ViewDirection
                        ? StaticRunDue::ViewDirection
                    : range.fiducial == ObjectRepresentation::RangeCheck::Distance
                        ? StaticRunDue::Distance
                        : StaticRunDue::AngleAround;
        due.measured = range.measured;
        due.threshold = range.threshold;
    } else if (inputsMoved > inputTolerance) {
        due.cause = StaticRunDue::StaticInput;
        due.measured = inputsMoved;
        due.threshold = inputTolerance;
    } else if (rep->imageHeight != camera.height) {
        due.cause = StaticRunDue::ImageSize;
        due.measured = static_cast<float>(camera.height);
        due.threshold = static_cast<float>(rep->imageHeight);
    } else if (rep->kind == Representation::Facets && slot.longestEdge > rep->maxEdgePixels) {
        due.cause = StaticRunDue::FacetsTooLong;
        due.measured = slot.longestEdge;
        due.threshold = rep->maxEdgePixels;
    } else {
        return std::nullopt;
    }
    return due;
}

void compareWithReference(ObjectSlot& slot, double storedSeconds, double referenceSeconds,
                          bool directAllowed, int slowFrames) {
    const ObjectRepresentation* rep = slot.representation.get();
    // A frame that built the object fills its first tiles: that is the build's cost, paid
    // once, and says nothing of the frames after.
    if (!rep || !slot.frameDynamic.drawn || slot.builtThisFrame ||
        rep->kind == Representation::Direct || !directAllowed || slot.goesDirect)
        return;
    slot.measuredMs = static_cast<float>(1e3 * storedSeconds);
    slot.referenceMs = static_cast<float>(1e3 * referenceSeconds);
    slot.framesSlowerThanReference =
        storedSeconds > referenceSeconds ? slot.framesSlowerThanReference + 1 : 0;
    // Far over (more than 4 times), one frame is evidence enough.
    if (slot.framesSlowerThanReference >= slowFrames || storedSeconds > 4.0 * referenceSeconds)
        slot.goesDirect = true;
}

std::vector<size_t> admitRebuilds(std::span<const size_t> due, std::span<const ObjectSlot> slots,
                                  double secondsLeft, std::vector<StaticRunDue>& dues,
                                  int& deferred) {
    std::vector<size_t> admitted, again;
    for (size_t i : due) (slots[i].representation ? again : admitted).push_back(i);
    std::sort(again.begin(), again.end(), [&](size_t a, size_t b) {
        return slots[a].rebuildSeconds < slots[b].rebuildSeconds;
    });
    for (size_t i : again) {
        const double cost = 1.5 * slots[i].rebuildSeconds;
        if (cost <= secondsLeft) {
            admitted.push_back(i);
            secondsLeft -= cost;
            continue;
        }
        ++deferred;
        for (StaticRunDue& d : dues)
            if (d.object == i) d.deferred = true;
    }
    std::sort(admitted.begin(), admitted.end());
    return admitted;
}

}  // namespace mpshade
