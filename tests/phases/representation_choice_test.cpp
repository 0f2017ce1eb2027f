// The representation auto picks (representation_choice.h): rules before the estimate,
// the single-phase estimate, maps that cannot fit, and how often an object is seen.
#include <gtest/gtest.h>

#include "phases/representation_choice.h"

namespace mpshade {
namespace {

TEST(RepresentationChoice, RulesBeforeTheEstimate) {
    ObjectCostInputs in;
    in.coveredPixels = 20000;
    in.frames = 48;
    in.staticCostUnits = 200;
    in.screenPixels = 320 * 180;
    in.combinedFacets = 1e7;  // far more than 4 per screen pixel
    EXPECT_EQ(chooseRepresentation(in).kind, Representation::ShaderMap)
        << chooseRepresentation(in).reason;
    in.combinedFacets = 2000;
    in.charts = 5000;  // a point cloud: its always-resident levels dwarf what it covers
    in.coveredPixels = 300;
    const RepresentationChoice points = chooseRepresentation(in);
    EXPECT_EQ(points.kind, Representation::Facets);
    EXPECT_NE(points.reason.find("always resident"), std::string::npos) << points.reason;
    // Found by fuzzing: the camera inside a large teapot, a tiny image. The map's pinned
    // levels dwarf the 12 points it covers, but facets for views that close number millions:
    // the facet rule comes first (it took 4 s where the reference took 0.2).
    in.combinedFacets = 3.9e6;
    in.charts = 32;
    in.coveredPixels = 12;
    in.screenPixels = 8 * 6;
    in.frames = 1;
    EXPECT_EQ(chooseRepresentation(in).kind, Representation::ShaderMap)
        << chooseRepresentation(in).reason;
    in.combinedFacets = 2000;
    in.charts = 5000;
    in.coveredPixels = 300;
    in.screenPixels = 320 * 180;
    in.frames = 48;
    in.haveMap = true;  // a map already built is paid for: facets would pay their static part
    in.staticCostUnits = 20000;
    EXPECT_EQ(chooseRepresentation(in).kind, Representation::ShaderMap)
        << chooseRepresentation(in).reason;
}

TEST(RepresentationChoice, SinglePhaseEstimateIsSamplesTimesRayAndShader) {
    // 1,000 covered pixels at 4 samples, a 100-unit shader: 4,000 x (100 x 0.3 + 350) ns.
    ObjectCostInputs in;
    in.coveredPixels = 1000.0;
    in.samplesPerPixel = 4;
    in.originalCostUnits = 100.0;
    in.staticCostUnits = 60.0;
    in.frames = 10;
    const RepresentationChoice c = chooseRepresentation(in);
    EXPECT_NEAR(c.singlePhaseFrameSeconds, 4000.0 * 380.0 * 1e-9, 1e-12);
    // The per-kind parts add up to the totals over the frames.
    EXPECT_NEAR(c.mapSeconds, c.mapStaticSeconds + 10.0 * c.mapFrameSeconds, 1e-12);
    EXPECT_NEAR(c.facetsSeconds, c.facetsStaticSeconds + 10.0 * c.facetsFrameSeconds, 1e-12);
    // Map texels go as the footprint's inverse square: at 8 samples and scale 1.2, 12 x 2 /
    // 4 = 6 a covered pixel, plus the chart's always-resident 34 x 34, each at the static
    // part's 60 units x 1.4 ns plus 60 ns of geometry.
    in.samplesPerPixel = 8;
    in.footprintScale = 1.2f;
    EXPECT_NEAR(chooseRepresentation(in).mapStaticSeconds,
                (1000.0 * 6.0 + 34.0 * 34.0) * (60.0 * 1.4 + 60.0) * 1e-9, 1e-9);
    // And as the footprints' elongation against a typical object's 2.5: a floor near the
    // horizon (12) fills 4.8 times the texels a covered pixel.
    in.elongation = 12.0;
    EXPECT_NEAR(chooseRepresentation(in).mapStaticSeconds,
                (1000.0 * 6.0 * 4.8 + 34.0 * 34.0) * (60.0 * 1.4 + 60.0) * 1e-9, 1e-9);
    in.elongation = 2.5;
    in.samplesPerPixel = 4;
    in.footprintScale = 0.6f;
    // Per pixel shades once a pixel but the reference still traces every sample.
    in.shadingRate = ShadingRate::Pixel;
    EXPECT_NEAR(chooseRepresentation(in).singlePhaseFrameSeconds, 4000.0 * 380.0 * 1e-9, 1e-12);
}

TEST(RepresentationChoice, MapsThatCannotFitAreNeverChosen) {
    // A cloud of 2,000,000 discs pinned 18M tiles in a pool of 4M and stopped the process;
    // the always-resident tiles now decide first, at their bound exactly.
    const RepresentationCostModel model;
    ObjectCostInputs in;
    in.combinedFacets = 1e9;  // facets would be hopeless too
    in.coveredPixels = 1e5;
    in.screenPixels = 1e5;
    in.pinnedTiles = model.maxPinnedTiles;
    std::string why;
    EXPECT_TRUE(shaderMapFits(in, why, model));
    EXPECT_EQ(chooseRepresentation(in, model).kind, Representation::ShaderMap);
    in.pinnedTiles = model.maxPinnedTiles + 1;
    EXPECT_FALSE(shaderMapFits(in, why, model));
    const RepresentationChoice c = chooseRepresentation(in, model);
    EXPECT_EQ(c.kind, Representation::Facets);
    EXPECT_NE(c.reason.find("always resident"), std::string::npos) << c.reason;
}

TEST(RepresentationChoice, SeenOftenAMapSeenOnceFacets) {
    // The same object: its map's static work pays back over many frames, not over one.
    ObjectCostInputs in;
    in.combinedFacets = 120000;  // 30 per covered pixel, as the survey finds on curved surfaces
    in.coveredPixels = 4000;
    in.charts = 16;
    in.staticCostUnits = 3000;  // expensive: noise and occlusion rays
    in.screenPixels = 320 * 180;
    // Fine map texels (12 a covered pixel): at one frame they cost more than the facets'
    // vertices; at the default footprint (about 4) the map would win even there.
    in.footprintScale = 0.6f;
    in.frames = 1;
    EXPECT_EQ(chooseRepresentation(in).kind, Representation::Facets);
    in.frames = 500;
    EXPECT_EQ(chooseRepresentation(in).kind, Representation::ShaderMap)
        << chooseRepresentation(in).reason;
}

TEST(RepresentationChoice, ACurvedObjectSeenForFramesIsAMapWhateverItsFacetsStaticCost) {
    // The courtyard's nearest column as `play` met it at 640 x 360 (24 frames, its 48
    // charts' always-resident levels filled up front): 16 facets a covered pixel. Its
    // points cost as much shaded from facets as from a map (docs/multiphase.md, "The cost
    // model's prices"), so the facets' rasterizing, 4.3 ms of CPU a frame, is not paid back
    // by their cheaper static run. At the old prices (290 ns a map point, 170 a facet point)
    // this was facets, 0.52 s against 0.58 s, and the courtyard's rasterizing doubled.
    ObjectCostInputs in;
    in.combinedFacets = 173106;
    in.coveredPixels = 10700;
    in.charts = 48;
    in.frames = 24;
    in.staticCostUnits = 1932;
    in.originalCostUnits = 2004;
    in.channels = 3;
    in.pinnedTiles = 48 * 9;
    in.pinnedBytes = 1679616;
    in.screenPixels = 640 * 360;
    const RepresentationChoice c = chooseRepresentation(in);
    EXPECT_EQ(c.kind, Representation::ShaderMap) << c.reason;
    // Each frame: 42,800 points at 100 ns against 173,106 facets at 25 ns and the points at 110.
    EXPECT_NEAR(c.mapFrameSeconds, 42800 * 100e-9, 1e-9);
    EXPECT_NEAR(c.facetsFrameSeconds, 173106 * 25e-9 + 42800 * 110e-9, 1e-9);
    // Seen for one frame, the facets' one static run (a vertex per two facets) is the cheaper.
    in.frames = 1;
    EXPECT_EQ(chooseRepresentation(in).kind, Representation::Facets)
        << chooseRepresentation(in).reason;
}

}  // namespace
}  // namespace mpshade
