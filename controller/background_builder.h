// background_builder.h -- rebuilds objects' representations on a worker thread beside the
// frames of a locked frame rate (MultiphaseOptions::backgroundRebuilds). An object whose
// view left its range is re-diced for the view of the frame that found it due, while the
// frames go on drawing its last representation; the controller swaps the new one in at the
// start of a frame after it is done (MultiphaseRenderer::adoptRebuilt). A rebuild costs a
// frame nothing then, however long it takes: admitted into a frame instead, a re-dice
// priced at 1.5 times its last run had cost 1.8-2.7 times that after the view moved far
// (the courtyard, docs/playback.md), and most missed deadlines were such frames. Patent
// col. 10-11: the controller schedules static work apart from the frames that need it.
//
// Only rebuilds that make no shader map are taken (StaticPhase::buildMakesMap): facets are
// built into storage of their own, and a kept map is only lent, so nothing the frames or
// the background filler read is written. The worker runs at idle priority on one thread of
// its own, like the background filler's (background_filler.h).
//
// Threads: every method is called from one controlling thread.
#pragma once

#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "phases/static_phase.h"

namespace mpshade {

// One object's rebuild for the view of the frame that found it due. Owns copies of the
// frame's animated parameters and lights, which the frame's own state does not keep past
// the frame.
struct RebuildJob {
    size_t object = 0;
    Representation kind = Representation::Auto;
    ObjectState state;
    CameraState camera;
    ShadingUniforms uniforms;  // its params and lights spans are re-pointed at the copies
    std::vector<float> params;
    std::vector<LightSample> lights;
    // The representation the frames draw meanwhile (lends its map); owned by the
    // controller, which keeps it until this job's result is adopted or dropped.
    const ObjectRepresentation* previous = nullptr;

    // The uniforms with their spans on this job's own copies.
    ShadingUniforms ownUniforms() const {
        ShadingUniforms u = uniforms;
        u.params = params;
        u.lights = lights;
        return u;
    }
};

struct RebuiltObject {
    RebuildJob job;
    std::unique_ptr<ObjectRepresentation> representation;
    // Its costs; seconds is the worker thread's CPU time, what the build costs a core when
    // it has one, not the wall time of a thread at idle priority.
    StaticCosts costs;
};

class BackgroundBuilder {
  public:
    // phase: the renderer's (not owned; must outlive the builder).
    explicit BackgroundBuilder(const StaticPhase& phase, bool idlePriority = true);
    ~BackgroundBuilder();
    BackgroundBuilder(const BackgroundBuilder&) = delete;
    BackgroundBuilder& operator=(const BackgroundBuilder&) = delete;

    // Queues job.object's rebuild, or, if it is queued and not started, brings it to this
    // job's view. One that is under way or done and not yet taken is left as it is.
    void submit(RebuildJob job);
    // Whether object's rebuild is queued, under way or done and not yet taken.
    bool pending(size_t object) const;
    // The rebuilds done since the last call, in the order they finished.
    std::vector<RebuiltObject> takeFinished();
    // Hands over a representation no frame will draw again (one a rebuild replaced) to be
    // freed on the worker: freeing a large mesh had taken a frame 2 ms. It must hold no
    // shader map (the caller drops its share first): maps are freed by the controller.
    void discard(std::unique_ptr<ObjectRepresentation> representation);
    // Drops the queue, waits for the rebuild under way and drops it and those done, and
    // frees the representations discarded.
    void cancel();
    // Waits until the queue is empty and nothing is under way (tests).
    void waitIdle();

  private:
    void run();

    const StaticPhase& phase_;
    bool idlePriority_;
    mutable std::mutex mutex_;
    std::condition_variable wake_, idle_;
    std::deque<RebuildJob> queue_;
    std::vector<RebuiltObject> finished_;
    std::vector<std::unique_ptr<ObjectRepresentation>> discarded_;
    bool busy_ = false, stop_ = false, dropCurrent_ = false;
    size_t current_ = 0;  // the object under way, while busy_
    std::thread worker_;
};

}  // namespace mpshade
