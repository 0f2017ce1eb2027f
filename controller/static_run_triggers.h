// static_run_triggers.h -- when an object goes back through the static phase (patent col.
// 11: the controller re-runs the static phase for an object whose range the view left;
// Lengyel and Snyder 1997, sec. 4-5: a cached rendering is valid while its geometric,
// sampling and photometric fiducials stay within their thresholds), and, under a frame
// budget, which of the due rebuilds fit the frame.
#pragma once

#include <optional>
#include <span>
#include <vector>

#include "controller/object_slot.h"
#include "phases/frame_stats.h"

namespace mpshade {

// Why object `object` (its slot, in this frame's `state` seen by `camera` with `uniforms`)
// must run its static phase now, checked in this order: never built; the view left its
// range (view direction, distance, angle around); an animated input its static part reads
// moved by more than `inputTolerance` of its span; the image height changed; combined
// facets measured longer than P/2 last frame; it goes direct (compareWithReference).
// Nothing: its representation still holds.
// `scratch`: reused storage for the inputs' values.
std::optional<StaticRunDue> staticRunDue(uint32_t object, const ObjectSlot& slot,
                                         const ObjectState& state, const CameraState& camera,
                                         const ShadingUniforms& uniforms, float inputTolerance,
                                         std::vector<float>& scratch);

// Never slower than single-phase, per object: after each frame, an object drawn from a
// stored representation (facets or a shader map) whose work that frame -- the tiles filled
// for it and the points shaded; a frame that built it does not count -- costs more
// (`storedSeconds`) than the reference renderer would have spent on its samples
// (`referenceSeconds`) counts a slow frame. `slowFrames` running, or one more than 4 times
// over, make it go direct (slot.goesDirect, then due as SlowerThanReference). Both figures
// are the cost model's for the frame's measured counts, not clock time, so the same frames
// make the same choice on every machine and run. An oblique floor whose footprints fill
// dozens of texels per covered pixel is the case: a direct representation runs the whole
// shader on facets at the geometric tolerance and stores nothing. Shaders that trace
// occlusion rays (not `directAllowed`) stay stored.
void compareWithReference(ObjectSlot& slot, double storedSeconds, double referenceSeconds,
                          bool directAllowed, int slowFrames = 2);

// A frame budget: what was never built is built; what is due again is rebuilt, cheapest
// first, only while its expected run (ObjectSlot::rebuildSeconds) and half as much again (a
// re-dice of a nearer view makes more facets) fits `secondsLeft`; the others are drawn from their
// last representation, marked deferred in `dues` and counted in `deferred`. Returns the objects to
// build now, in index order.
std::vector<size_t> admitRebuilds(std::span<const size_t> due, std::span<const ObjectSlot> slots,
                                  double secondsLeft, std::vector<StaticRunDue>& dues,
                                  int& deferred);

}  // namespace mpshade
