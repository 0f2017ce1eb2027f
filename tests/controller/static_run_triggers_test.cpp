// When an object's static phase is due again for the sampling fiducials (the image height,
// combined facets longer than P/2, at the bound exactly and just past it), and which due
// rebuilds a frame budget admits: never-built objects always, rebuilds cheapest first while
// 1.5 times their last run fits the time left (at it exactly too), the rest marked deferred.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "controller/static_run_triggers.h"

namespace mpshade {
namespace {

// Slots 0..n-1: those with a cost were built before (their last run took it, seconds);
// those without never were.
std::vector<ObjectSlot> slots(const std::vector<double>& lastRun) {
    std::vector<ObjectSlot> out(lastRun.size());
    for (size_t i = 0; i < lastRun.size(); ++i) {
        if (lastRun[i] < 0.0) continue;
        out[i].representation = std::make_unique<ObjectRepresentation>();
        out[i].rebuildSeconds = lastRun[i];
    }
    return out;
}

std::vector<StaticRunDue> dues(const std::vector<size_t>& objects) {
    std::vector<StaticRunDue> out;
    for (size_t i : objects) {
        StaticRunDue d;
        d.object = static_cast<uint32_t>(i);
        d.cause = StaticRunDue::Distance;
        out.push_back(d);
    }
    return out;
}

// An object built for the view it is seen from now (no geometric fiducial moves), `kind`,
// at an image 270 pixels tall with P/2 = 0.5 pixel.
struct BuiltForThisView {
    ObjectSlot slot;
    ObjectState state;
    CameraState camera;
    ShadingUniforms uniforms;
    std::vector<float> scratch;

    explicit BuiltForThisView(Representation kind) {
        state.eye = glm::vec3(0.0f, 1.0f, 5.0f);
        camera.eye = state.eye;
        camera.forward = glm::vec3(0.0f, 0.0f, -1.0f);
        camera.height = 270;
        auto rep = std::make_unique<ObjectRepresentation>();
        rep->kind = kind;
        rep->representativeEye = state.eye;
        rep->representativeForward = camera.forward;
        rep->center = glm::vec3(0.0f);
        rep->imageHeight = 270;
        rep->maxEdgePixels = 0.5f;
        slot.representation = std::move(rep);
    }
    std::optional<StaticRunDue> due() {
        return staticRunDue(3, slot, state, camera, uniforms, 0.05f, scratch);
    }
};

TEST(StaticRunDue, AnyOtherImageHeightIsDueWithBothHeights) {
    for (int height : {135, 269, 271, 540}) {
        BuiltForThisView b(Representation::ShaderMap);
        b.camera.height = height;
        const std::optional<StaticRunDue> d = b.due();
        ASSERT_TRUE(d) << height;
        EXPECT_EQ(d->cause, StaticRunDue::ImageSize);
        EXPECT_EQ(d->object, 3u);
        EXPECT_EQ(d->measured, static_cast<float>(height));
        EXPECT_EQ(d->threshold, 270.0f);
    }
    BuiltForThisView same(Representation::ShaderMap);
    EXPECT_FALSE(same.due());
}

TEST(StaticRunDue, CombinedFacetsPastPOverTwoAreDueAtTheBoundNot) {
    BuiltForThisView b(Representation::Facets);
    b.slot.longestEdge = 0.5f;  // exactly P/2: still holds
    EXPECT_FALSE(b.due());
    for (float longest : {std::nextafter(0.5f, 1.0f), 0.75f, 0.99f}) {
        b.slot.longestEdge = longest;
        const std::optional<StaticRunDue> d = b.due();
        ASSERT_TRUE(d) << longest;
        EXPECT_EQ(d->cause, StaticRunDue::FacetsTooLong);
        EXPECT_EQ(d->measured, longest);
        EXPECT_EQ(d->threshold, 0.5f);
    }
    // A separate representation's facets carry no n-tuple: their length is not a fiducial.
    BuiltForThisView map(Representation::ShaderMap);
    map.slot.longestEdge = 5.0f;
    EXPECT_FALSE(map.due());
}

TEST(CompareWithReference, TwoFramesRunningCostlierThanTheReferenceGoDirect) {
    BuiltForThisView b(Representation::ShaderMap);
    b.slot.frameDynamic.drawn = true;
    // At the reference's cost exactly: not slower.
    compareWithReference(b.slot, 0.010, 0.010, true);
    EXPECT_EQ(b.slot.framesSlowerThanReference, 0);
    compareWithReference(b.slot, 0.011, 0.010, true);
    EXPECT_EQ(b.slot.framesSlowerThanReference, 1);
    EXPECT_FALSE(b.slot.goesDirect);
    // A frame that built the object counts neither way; a cheaper frame starts again.
    b.slot.builtThisFrame = true;
    compareWithReference(b.slot, 0.5, 0.010, true);
    EXPECT_EQ(b.slot.framesSlowerThanReference, 1);
    b.slot.builtThisFrame = false;
    compareWithReference(b.slot, 0.009, 0.010, true);
    EXPECT_EQ(b.slot.framesSlowerThanReference, 0);
    compareWithReference(b.slot, 0.020, 0.010, true);
    compareWithReference(b.slot, 0.030, 0.010, true);
    EXPECT_TRUE(b.slot.goesDirect);
    EXPECT_FLOAT_EQ(b.slot.measuredMs, 30.0f);
    EXPECT_FLOAT_EQ(b.slot.referenceMs, 10.0f);
    // Then it is due, as SlowerThanReference, with both figures.
    const std::optional<StaticRunDue> d = b.due();
    ASSERT_TRUE(d);
    EXPECT_EQ(d->cause, StaticRunDue::SlowerThanReference);
    EXPECT_FLOAT_EQ(d->measured, 30.0f);
    EXPECT_FLOAT_EQ(d->threshold, 10.0f);
}

TEST(CompareWithReference, OneFrameMoreThanFourTimesOverGoesDirectAtOnce) {
    BuiltForThisView atFour(Representation::ShaderMap), past(Representation::ShaderMap);
    atFour.slot.frameDynamic.drawn = past.slot.frameDynamic.drawn = true;
    compareWithReference(atFour.slot, 0.040, 0.010, true);  // four times exactly: one frame
    EXPECT_FALSE(atFour.slot.goesDirect);
    EXPECT_EQ(atFour.slot.framesSlowerThanReference, 1);
    compareWithReference(past.slot, std::nextafter(0.040, 1.0), 0.010, true);
    EXPECT_TRUE(past.slot.goesDirect);
}

TEST(CompareWithReference, NeverForShadersTracingRaysNorObjectsNotDrawnOrAlreadyDirect) {
    BuiltForThisView rays(Representation::ShaderMap);
    rays.slot.frameDynamic.drawn = true;
    BuiltForThisView hidden(Representation::ShaderMap);
    BuiltForThisView direct(Representation::Direct);
    direct.slot.frameDynamic.drawn = true;
    for (int frame = 0; frame < 4; ++frame) {
        compareWithReference(rays.slot, 1.0, 0.01, false);
        compareWithReference(hidden.slot, 1.0, 0.01, true);
        compareWithReference(direct.slot, 1.0, 0.01, true);
    }
    EXPECT_FALSE(rays.slot.goesDirect);
    EXPECT_FALSE(hidden.slot.goesDirect);
    EXPECT_FALSE(direct.slot.goesDirect);
    EXPECT_FALSE(rays.due());
}

TEST(AdmitRebuilds, CheapestFirstWhileHalfAsMuchAgainFitsAtTheBoundaryToo) {
    // Object 0 never built; 1, 2, 3 built with last runs of 0.04, 0.01, 0.02 s. With 0.045 s
    // left: 2 (0.015) then 3 (0.03, leaving exactly 0) fit; 1 (0.06) does not.
    const std::vector<ObjectSlot> s = slots({-1.0, 0.04, 0.01, 0.02});
    const std::vector<size_t> due = {0, 1, 2, 3};
    std::vector<StaticRunDue> d = dues(due);
    int deferred = 0;
    const std::vector<size_t> admitted = admitRebuilds(due, s, 0.045, d, deferred);
    EXPECT_EQ(admitted, (std::vector<size_t>{0, 2, 3}));  // in index order
    EXPECT_EQ(deferred, 1);
    EXPECT_FALSE(d[0].deferred);
    EXPECT_TRUE(d[1].deferred);
    EXPECT_FALSE(d[2].deferred);
    EXPECT_FALSE(d[3].deferred);
}

TEST(AdmitRebuilds, ARebuildJustOverTheTimeLeftIsDeferredButANewObjectIsNot) {
    const std::vector<ObjectSlot> s = slots({0.02, -1.0});
    const std::vector<size_t> due = {0, 1};
    std::vector<StaticRunDue> d = dues(due);
    int deferred = 0;
    const std::vector<size_t> admitted = admitRebuilds(due, s, 0.0299, d, deferred);
    EXPECT_EQ(admitted, (std::vector<size_t>{1}));
    EXPECT_EQ(deferred, 1);
    EXPECT_TRUE(d[0].deferred);
    // No time left at all: the never-built object is still built.
    std::vector<StaticRunDue> none = dues(due);
    int deferredNone = 0;
    EXPECT_EQ(admitRebuilds(due, s, -1.0, none, deferredNone), (std::vector<size_t>{1}));
}

}  // namespace
}  // namespace mpshade
