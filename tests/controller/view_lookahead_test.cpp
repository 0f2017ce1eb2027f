// Which view an object's static phase is built for, on views made here with known angles.
#include "controller/view_lookahead.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

namespace mpshade {
namespace {

// An eye `degrees` around the y axis from +z, `distance` from the origin, looking at it.
ObjectViewpoint orbitView(float degrees, float distance = 10.0f) {
    const float a = degrees * 3.14159265f / 180.0f;
    ObjectViewpoint v;
    v.eye = {distance * std::sin(a), 0.0f, distance * std::cos(a)};
    v.forward = -v.eye / distance;
    return v;
}

RangeOptions range10() {
    RangeOptions r;
    r.angle = 10.0f;
    r.distanceFactor = 2.0f;
    return r;
}

TEST(ViewLookahead, ASteadyOrbitIsBuiltForTheViewWhoseRangeReachesFurthest) {
    // 1.875 degrees a frame: view c's 10-degree range holds views c - 5 .. c + 5, so of the
    // first 9 views the one holding the longest run from view 0 is view 5 (views 0-10).
    std::vector<ObjectViewpoint> views;
    for (int f = 0; f <= 16; ++f) views.push_back(orbitView(1.875f * static_cast<float>(f)));
    EXPECT_EQ(holdingView(views, 8, {0.0f, 0.0f, 0.0f}, range10()), 5u);
    // Only the first three may be chosen: the last of them reaches furthest.
    EXPECT_EQ(holdingView(views, 2, {0.0f, 0.0f, 0.0f}, range10()), 2u);
    // A range must hold the present view: at 12 degrees a frame no later view's does.
    std::vector<ObjectViewpoint> fast;
    for (int f = 0; f <= 16; ++f) fast.push_back(orbitView(12.0f * static_cast<float>(f)));
    EXPECT_EQ(holdingView(fast, 8, {0.0f, 0.0f, 0.0f}, range10()), 0u);
}

TEST(ViewLookahead, ACameraWanderingAboutThePresentViewKeepsIt) {
    // Every view within 8 degrees of view 0, to either side: view 0's range holds them all,
    // and a view 8 degrees off holds only those on its side.
    std::vector<ObjectViewpoint> views;
    for (int f = 0; f <= 16; ++f)
        views.push_back(orbitView(f % 2 == 0 ? 0.0f : (f % 4 == 1 ? 8.0f : -8.0f)));
    EXPECT_EQ(holdingView(views, 8, {0.0f, 0.0f, 0.0f}, range10()), 0u);
}

TEST(ViewLookahead, ViewsAfterTheObjectMovesAreNotConsidered) {
    std::vector<ObjectViewpoint> views;
    for (int f = 0; f <= 16; ++f) views.push_back(orbitView(1.875f * static_cast<float>(f)));
    for (size_t f = 3; f < views.size(); ++f) views[f].objectToWorld[3][0] = 1.0f;  // moved
    // Views 0-2 remain, and each of them holds all three: the present view (with the moved
    // views considered, view 5, as in the orbit above).
    EXPECT_EQ(holdingView(views, 8, {0.0f, 0.0f, 0.0f}, range10()), 0u);
}

TEST(ViewLookahead, TheDistanceBoundsTheRangeToo) {
    // A dolly straight in, 10 -> 2.5 over 8 frames: with a factor of 2, view c holds the
    // views within a factor of 2 of its distance; the view holding the longest run from
    // the first (distance 10) is the one at 5 (views 0-8 down to 2.5).
    std::vector<ObjectViewpoint> views;
    for (int f = 0; f <= 8; ++f) {
        ObjectViewpoint v = orbitView(0.0f, 10.0f - 0.9375f * static_cast<float>(f));
        views.push_back(v);
    }
    // Distances 10, 9.0625, ..., 2.5. View c at d_c holds the views at [d_c / 2, 2 d_c]: view
    // 4 (6.25) and view 5 (5.3125) each hold views 0-7 (3.4375; view 8, 2.5, is too near),
    // view 6 (4.375) not view 0 (10 > 8.75), view 3 (7.1875) only views 0-6: of the two
    // equal runs, the earlier view.
    EXPECT_EQ(holdingView(views, 8, {0.0f, 0.0f, 0.0f}, range10()), 4u);
}

}  // namespace
}  // namespace mpshade
