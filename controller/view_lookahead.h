// view_lookahead.h -- which frame's view an object's static phase is built for. A range
// (the view distance within a factor, the direction around the object and the view
// direction within an angle) holds on both sides of its representative view, so a
// representation built for the view a few frames ahead serves the frames before it as well
// as those after: where the camera's path is known (the scene's keys), the controller
// builds for the view ahead whose range holds the longest run of frames from the present
// one, and a camera moving steadily goes back through the static phase less often (patent
// col. 11, the controller re-running the static phase when the view leaves the range;
// Fearing 2000, predicting the views to come rather than reacting to them).
#pragma once

#include <span>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "scene/scene.h"

namespace mpshade {

// One frame's view of an object: the eye and view direction in its own space, and where it
// stands in the world.
struct ObjectViewpoint {
    glm::vec3 eye{0.0f};
    glm::vec3 forward{0.0f, 0.0f, -1.0f};  // unit
    glm::mat4 objectToWorld{1.0f};
};

// Which of views[0 .. candidates] to build for: the one whose range (`range` around
// `center`, object space; its view direction checked too, as for a representation whose
// patches were frustum culled) holds the longest run of views from views[0] on, views[0]
// among them; of equal runs, the earliest (the present view first). views[0] is the frame
// being rendered, the rest the frames after it; views from the first whose placement
// differs from views[0]'s are not considered (the object moved, and what its static phase
// computes may depend on where it stands). A camera on a steady path gets a view ahead
// (its range reaches back to the present and on past it); one wandering about the present
// view keeps that.
size_t holdingView(std::span<const ObjectViewpoint> views, size_t candidates,
                   const glm::vec3& center, const RangeOptions& range);

}  // namespace mpshade
