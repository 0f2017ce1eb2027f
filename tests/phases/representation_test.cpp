// The static phase's representations and the dynamic phase over them: dicing to its two
// targets, facets clipped at the near plane, the representation auto picks, shading rates,
// the maps' memory budget, and the grazing floor against a 64-sample reference.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "controller/multiphase_renderer.h"
#include "phases/dicing.h"
#include "phases/facet_clipping.h"
#include "phases/facet_rasterizer.h"
#include "phases/fixed_point_warp.h"
#include "phases/image_compare.h"
#include "phases/reference_renderer.h"
#include "phases/representation_choice.h"
#include "test_support.h"

namespace mpshade {
namespace {

// A dicing view of a camera at `eye` looking at `target`, both in the object's own space
// (the object at the origin, unscaled), for an image `height` pixels tall with a 40 degree
// field of view.
struct View {
    CameraState camera;
    DicingView dicing;
    View(const glm::vec3& eye, const glm::vec3& target, int width, int height) {
        camera.eye = eye;
        camera.forward = glm::normalize(target - eye);
        camera.right = glm::normalize(glm::cross(camera.forward, glm::vec3(0, 1, 0)));
        camera.up = glm::cross(camera.right, camera.forward);
        camera.tanHalfFovY = std::tan(glm::radians(20.0f));
        camera.aspect = float(width) / float(height);
        camera.zNear = 0.01f;
        camera.zFar = 1000.0f;
        camera.width = width;
        camera.height = height;
        dicing.eye = eye;
        dicing.pixelsPerUnit = 0.5f * height / camera.tanHalfFovY;
        const float tx = camera.tanHalfFovY * camera.aspect, ty = camera.tanHalfFovY;
        dicing.fovSlack = 1.0f + tx * tx + ty * ty;
        dicing.nearDistance = camera.zNear;
        dicing.forward = camera.forward;
        dicing.halfDiagonalFov = std::atan(std::sqrt(tx * tx + ty * ty));
        dicing.projects = true;
        objectToScreen(glm::mat4(1.0f), camera, dicing.screen);
        dicing.nearW = camera.zNear;
    }
    bool project(const glm::vec3& p, glm::dvec2& out) const {
        double h[3];
        for (int r = 0; r < 3; ++r)
            h[r] = dicing.screen[r][0] * p.x + dicing.screen[r][1] * p.y +
                   dicing.screen[r][2] * p.z + dicing.screen[r][3];
        if (!(h[2] > 0.0)) return false;
        out = glm::dvec2(h[0] / h[2], h[1] / h[2]);
        return true;
    }
};

const DicingOptions kFlat = {DicingTarget::Flatness, 0.5f, 0.25f, true};
const DicingOptions kEdges = {DicingTarget::EdgeLength, 0.5f, 0.25f, false};

TEST(Dicing, AFlatChartIsTwoTriangles) {
    const Surface plane = Plane{400.0f, 400.0f};
    const View view(glm::vec3(0, 0.25f, 100), glm::vec3(0.5f, 0.2f, 80), 320, 180);
    const DicedSurface d = diceSurface(plane, view.dicing, RangeOptions{}, kFlat);
    EXPECT_EQ(d.triangles.size(), 6u);
    EXPECT_EQ(d.qx.size(), 4u);
}

TEST(Dicing, FlatnessHoldsAQuarterPixelAtTheRepresentativeView) {
    // Every facet edge's midpoint against the surface point at the midpoint's chart
    // coordinates, projected: within 1/4 pixel (the survey measures chords between its
    // grid points, so allow it 10%), over a sphere and a torus seen from nearby. At a
    // sphere's poles the chart's u collapses: an edge from a pole follows the other end's
    // meridian, so that is where its midpoint is judged.
    RangeOptions range;
    range.distanceFactor = 1.25f;
    for (const Surface& surface : {Surface{Sphere{1.0f}}, Surface{Torus{1.0f, 0.35f}}}) {
        const View view(glm::vec3(0.3f, 0.8f, 3.2f), glm::vec3(0.0f), 640, 360);
        const DicedSurface d = diceSurface(surface, view.dicing, range, kFlat);
        double worst = 0.0;
        for (size_t f = 0; f < d.triangles.size(); f += 3)
            for (int e = 0; e < 3; ++e) {
                const uint32_t a = d.triangles[f + e], b = d.triangles[f + (e + 1) % 3];
                const ChartPoint& ca = d.attributePoints[a];
                const ChartPoint& cb = d.attributePoints[b];
                const SurfaceSample& ga = d.attributeGeometry[a];
                const SurfaceSample& gb = d.attributeGeometry[b];
                auto collapsed = [](const SurfaceSample& g) {
                    return glm::length(g.dPdu) < 1e-4f * glm::length(g.dPdv);
                };
                const float u = collapsed(ga) ? cb.u : collapsed(gb) ? ca.u : 0.5f * (ca.u + cb.u);
                const glm::vec3 surfaceMid =
                    evaluate(surface, {ca.chart, u, 0.5f * (ca.v + cb.v)}).P;
                const glm::vec3 chordPoint = 0.5f * (ga.P + gb.P);
                glm::dvec2 p, q;
                if (view.project(chordPoint, p) && view.project(surfaceMid, q))
                    worst = std::max(worst, glm::length(p - q));
            }
        EXPECT_LE(worst, 0.25 * 1.1) << surfaceTypeName(surface);
        EXPECT_GT(worst, 0.02) << "diced far finer than asked";
        EXPECT_LT(d.triangles.size() / 3, 100000u) << surfaceTypeName(surface);
    }
}

TEST(Dicing, EdgesUnderHalfAPixelAtTheRepresentativeView) {
    // The combined representation: projected edges at most P/2 at the representative view
    // for 97% of them (measured: 97.7%); the rest are transition facets between patches of
    // different rates and chords the survey between grid points does not see, within a
    // third more (measured: 0.666 at most; the renderer dices again past the longest a
    // representation started with). Most edges over P/8.
    const Surface sphere = Sphere{1.0f};
    const View view(glm::vec3(0.4f, 0.3f, 4.0f), glm::vec3(0.0f), 320, 180);
    const DicedSurface d = diceSurface(sphere, view.dicing, RangeOptions{}, kEdges);
    double longest = 0.0;
    size_t tiny = 0, edges = 0, over = 0;
    for (size_t f = 0; f < d.triangles.size(); f += 3)
        for (int e = 0; e < 3; ++e) {
            glm::dvec2 p, q;
            if (!view.project(d.attributeGeometry[d.triangles[f + e]].P, p) ||
                !view.project(d.attributeGeometry[d.triangles[f + (e + 1) % 3]].P, q))
                continue;
            const double l = glm::length(p - q);
            longest = std::max(longest, l);
            ++edges;
            tiny += l < 0.125 ? 1 : 0;
            over += l > 0.5 ? 1 : 0;
        }
    EXPECT_LT(static_cast<double>(over) / edges, 0.03);
    EXPECT_LE(longest, 0.5 * 4.0 / 3.0);
    EXPECT_LT(static_cast<double>(tiny) / edges, 0.35);
}

TEST(FacetClipping, FacetsAcrossTheNearPlaneStayWatertight) {
    // A quad of two triangles lying on the floor, from a camera just above it: two of its
    // corners are behind the eye. Clipped, the two triangles must still cover every sample
    // of the visible floor exactly once (the translucent path counts every facet hit).
    FacetMesh mesh;
    Bounds3 b;
    b.extend(glm::vec3(-50, 0, -50));
    b.extend(glm::vec3(50, 0.001f, 50));
    mesh.format = FixedPointFormat::forBounds(b);
    for (const glm::vec3& p : {glm::vec3(-50, 0, -50), glm::vec3(50, 0, -50), glm::vec3(50, 0, 50),
                               glm::vec3(-50, 0, 50)}) {
        mesh.qx.push_back(mesh.format.quantize(p.x, 0));
        mesh.qy.push_back(mesh.format.quantize(p.y, 1));
        mesh.qz.push_back(mesh.format.quantize(p.z, 2));
    }
    mesh.positionIndex = {0, 2, 1, 0, 3, 2};  // the shared diagonal crosses the near plane
    mesh.attributeIndex = mesh.positionIndex;
    const View view(glm::vec3(3, 0.3f, 4), glm::vec3(-2, 0.1f, -6), 96, 54);
    const FixedPointWarp warp(glm::mat4(1.0f), view.camera, mesh.format);
    WarpedVertices warped;
    warp.warp(mesh.qx.data(), mesh.qy.data(), mesh.qz.data(), 4, warped);
    ASSERT_TRUE(warped.culled(0) || warped.culled(1) || warped.culled(2) || warped.culled(3));
    const SampleLayout layout(96, 54, 16, 3u);
    VisibilityBuffer vis;
    RasterStats stats;
    RasterOptions options;
    options.layers = 4;
    rasterizeFacets({{&mesh, &warped, &warp, false}}, layout, 1000.0f, options, vis, stats);
    EXPECT_GT(stats.facetsClipped, 0u);
    int floor = 0;
    for (size_t s = 0; s < layout.count(); ++s) {
        // Below the horizon the floor fills the view (it reaches 50 units out).
        const glm::vec3 d = view.camera.direction(layout.x(s), layout.y(s));
        if (d.y > -0.01f) continue;
        const float t = -0.3f / d.y;
        const glm::vec3 hit = view.camera.eye + t * d;
        if (std::fabs(hit.x) > 49.0f || std::fabs(hit.z) > 49.0f) continue;
        ++floor;
        ASSERT_EQ(vis.count[s], 1)
            << "sample " << s << " at (" << layout.x(s) << ", " << layout.y(s) << ")";
    }
    EXPECT_GT(floor, 20000);
}

// Is (x, y) inside triangle (a, b, c), and how far from its nearest edge line (pixels)?
bool insideTriangle(const glm::dvec2 v[3], double x, double y, double& edgeDistance) {
    int positive = 0, negative = 0;
    edgeDistance = 1e300;
    for (int e = 0; e < 3; ++e) {
        const glm::dvec2 a = v[e], b = v[(e + 1) % 3];
        const double cross = (b.x - a.x) * (y - a.y) - (b.y - a.y) * (x - a.x);
        edgeDistance = std::min(edgeDistance, std::fabs(cross) / glm::length(b - a));
        positive += cross > 0.0, negative += cross < 0.0;
    }
    return positive == 0 || negative == 0;
}

TEST(FacetClipping, GuardBandOnBothAxes) {
    // A square of two facets seen so close that it spans about 160 000 pixels each way,
    // and three more facets crossing the guard band (|x|, |y| <= 32768 pixels) on x only,
    // on y only, and on both. Clipped, every corner lies in the band, and the clipped
    // triangles cover exactly the points of the band the exact facet covers (points on a
    // grid through the band and just inside its edges, away from the facet's own edges);
    // the square's two halves share the corners where their diagonal leaves the band.
    FacetMesh mesh;
    Bounds3 b;
    b.extend(glm::vec3(-1, -1, -0.001f));
    b.extend(glm::vec3(1, 1, 0.001f));
    mesh.format = FixedPointFormat::forBounds(b);
    const glm::vec2 corners[] = {{-1, -1},   {1, -1},       {1, 1},          {-1, 1},  // square
                                 {-1, 0},    {0.2f, -0.2f}, {0.25f, 0.25f},            // x only
                                 {0, -1},    {0.2f, 0.2f},  {-0.25f, 0.25f},           // y only
                                 {-1, 0.9f}, {0.9f, -1},    {0.1f, 0.1f}};             // both
    for (const glm::vec2& c : corners) {
        mesh.qx.push_back(mesh.format.quantize(c.x, 0));
        mesh.qy.push_back(mesh.format.quantize(c.y, 1));
        mesh.qz.push_back(mesh.format.quantize(0.0f, 2));
    }
    mesh.positionIndex = {0, 1, 2, 0, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
    mesh.attributeIndex = mesh.positionIndex;
    View view(glm::vec3(0, 0, 5), glm::vec3(0.0f), 320, 240);
    view.camera.tanHalfFovY = 3e-4f;  // 1 object unit is about 80 000 pixels
    const FixedPointWarp warp(glm::mat4(1.0f), view.camera, mesh.format);
    WarpedVertices warped;
    warp.warp(mesh.qx.data(), mesh.qy.data(), mesh.qz.data(), mesh.qx.size(), warped);

    constexpr double G = FixedPointWarp::kGuardBand;
    std::vector<double> probes;
    for (double p = -G + 0.25; p < G; p += 997.0) probes.push_back(p);
    for (double p : {-G + 0.25, -G + 0.75, G - 0.75, G - 0.25}) probes.push_back(p);
    std::vector<std::vector<ScreenTriangle>> clipped;
    for (size_t f = 0; f < mesh.positionIndex.size(); f += 3) {
        const uint32_t* p = &mesh.positionIndex[f];
        glm::dvec2 exact[3];
        bool crossesX = false, crossesY = false;
        for (int i = 0; i < 3; ++i) {
            ASSERT_TRUE(warp.warpExact(mesh.qx[p[i]], mesh.qy[p[i]], mesh.qz[p[i]], exact[i].x,
                                       exact[i].y));
            crossesX |= std::fabs(exact[i].x) > G, crossesY |= std::fabs(exact[i].y) > G;
            ASSERT_EQ(warped.culled(p[i]), std::fabs(exact[i].x) > G || std::fabs(exact[i].y) > G);
        }
        if (f == 6) {
            EXPECT_TRUE(crossesX && !crossesY);
        } else if (f == 9) {
            EXPECT_TRUE(!crossesX && crossesY);
        } else if (f == 12) {
            EXPECT_TRUE(crossesX && crossesY);
        }
        ScreenTriangle out[6];
        const int n = clipFacet(warp, mesh, warped, p, out);
        ASSERT_GT(n, 0) << "facet " << f / 3;
        clipped.emplace_back(out, out + n);
        constexpr int32_t kBand = int32_t(G) * 256;
        for (const ScreenTriangle& t : clipped.back())
            for (int i = 0; i < 3; ++i) {
                ASSERT_LE(std::abs(t.x[i]), kBand) << "facet " << f / 3;
                ASSERT_LE(std::abs(t.y[i]), kBand) << "facet " << f / 3;
                ASSERT_GT(t.invDepth[i], 0.0f);
            }
        int inside = 0;
        for (double x : probes)
            for (double y : probes) {
                double distance;
                const bool in = insideTriangle(exact, x, y, distance);
                if (distance < 2.0) continue;
                bool covered = false;
                for (const ScreenTriangle& t : clipped.back()) {
                    glm::dvec2 v[3];
                    for (int i = 0; i < 3; ++i) v[i] = glm::dvec2(t.x[i], t.y[i]) / 256.0;
                    double unused;
                    covered |= insideTriangle(v, x, y, unused);
                }
                ASSERT_EQ(covered, in) << "facet " << f / 3 << " at (" << x << ", " << y << ")";
                inside += in;
            }
        EXPECT_GT(inside, 100) << "facet " << f / 3;
    }
    // The square's halves: each corner one makes on the diagonal, the other makes too.
    auto cornersOf = [&](int facet) {
        std::vector<std::pair<int32_t, int32_t>> c;
        for (const ScreenTriangle& t : clipped[facet])
            for (int i = 0; i < 3; ++i) c.emplace_back(t.x[i], t.y[i]);
        std::sort(c.begin(), c.end());  // the fan repeats its first corner: count each once
        c.erase(std::unique(c.begin(), c.end()), c.end());
        return c;
    };
    const auto lower = cornersOf(0), upper = cornersOf(1);
    int shared = 0;
    for (const auto& c : lower)
        if (std::find(upper.begin(), upper.end(), c) != upper.end()) ++shared;
    EXPECT_GE(shared, 2) << "the clipped diagonal's two ends";
}

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

Image renderTruth(const Scene& scene, int frame, int width, int height) {
    ReferenceRenderer reference(scene);
    RenderOptions dense;
    dense.width = width, dense.height = height, dense.samplesPerPixel = 64;
    FrameStats stats;
    return reference.renderFrame(frame, dense, stats);
}

TEST(MultiphaseRenderer, GrazingFloorBeatsTheReferenceAtTheSameSamples) {
    // A 400 x 400 tiled floor from a quarter unit above it: two facets, a shader map from
    // level 0 at 2^20 texels a side, Feline probes. Against 64 samples per pixel, it must do
    // at least as well as the reference renderer at the same 4 samples (measured: about
    // 1.5 dB better, the map's filtering against the reference's aliasing).
    const Scene scene = loadScene(test::sourcePath("tests/data/scenes/grazing_floor.json"));
    ReferenceRenderer reference(scene);
    MultiphaseRenderer multi(scene);
    RenderOptions options;
    options.width = 160, options.height = 90;
    for (int frame : {0, 5}) {
        const Image truth = renderTruth(scene, frame, 160, 90);
        FrameStats rs, ms;
        const Image ref = reference.renderFrame(frame, options, rs);
        const Image got = multi.renderFrame(frame, options, ms);
        const double mp = compareImages(got, truth).psnr, rp = compareImages(ref, truth).psnr;
        EXPECT_GE(mp, rp) << "frame " << frame;
        EXPECT_EQ(ms.dynamic.facets, 2u);
        EXPECT_EQ(ms.nonFiniteSamples, 0u);
        EXPECT_EQ(ms.dynamic.probeFallbacks, 0u) << "render fills every tile before shading";
        RecordProperty("grazing_psnr_multiphase_" + std::to_string(frame), std::to_string(mp));
        RecordProperty("grazing_psnr_reference_" + std::to_string(frame), std::to_string(rp));
    }
}

TEST(MultiphaseRenderer, PixelRateShadesOncePerPixelAndSurface) {
    Scene scene = loadScene(test::sourcePath("examples/teapot/scene.json"));
    RenderOptions options;
    options.width = 120, options.height = 80;
    ReferenceRenderer reference(scene);
    FrameStats rs, sample, pixel;
    const Image ref = reference.renderFrame(1, options, rs);
    MultiphaseOptions perSample, perPixel;
    perSample.shadingRate = ShadingRate::Sample;
    perPixel.shadingRate = ShadingRate::Pixel;
    MultiphaseRenderer a(scene, perSample), b(scene, perPixel);
    const Image imageA = a.renderFrame(1, options, sample);
    const Image imageB = b.renderFrame(1, options, pixel);
    // Per sample: a point per visible sample. Per pixel: one per pixel and surface, so
    // between a point per covered pixel and spp of them on silhouettes.
    const double spp = scene.settings.samplesPerPixel;
    EXPECT_GT(sample.shadedPoints, pixel.shadedPoints * (spp - 0.5));
    EXPECT_LT(pixel.shadedPoints, sample.shadedPoints / spp * 1.2);
    // Against the reference's own samples (measured: 36.2 and 30.7 dB; the maps prefilter
    // the mortar lines the reference aliases, and per pixel they are blurred once more).
    EXPECT_GT(compareImages(imageA, ref).psnr, 34.0);
    EXPECT_GT(compareImages(imageB, ref).psnr, 28.5);
    EXPECT_LT(compareImages(imageB, ref).coverageDiff, 0.01);
    // At 4 samples a pixel point's footprint (half a pixel) is a sample's (1 / sqrt(4)):
    // the same map levels, so about as many tiles (a pixel's point at the pixel centre
    // reaches a few fewer at the edges of what is seen).
    RecordProperty("tiles_sample", std::to_string(sample.tiles.requested));
    RecordProperty("tiles_pixel", std::to_string(pixel.tiles.requested));
    EXPECT_GT(pixel.tiles.requested, sample.tiles.requested * 3 / 4);
    EXPECT_LE(pixel.tiles.requested, sample.tiles.requested);
}

TEST(MultiphaseRenderer, QuadRateShadesOncePerTwoByTwoPixelsAndSurface) {
    Scene scene = loadScene(test::sourcePath("examples/teapot/scene.json"));
    RenderOptions options;
    options.width = 120, options.height = 80;
    ReferenceRenderer reference(scene);
    FrameStats rs, pixel, quad;
    const Image ref = reference.renderFrame(1, options, rs);
    MultiphaseOptions perPixel, perQuad;
    perPixel.shadingRate = ShadingRate::Pixel;
    perQuad.shadingRate = ShadingRate::Quad;
    MultiphaseRenderer a(scene, perPixel), b(scene, perQuad);
    a.renderFrame(1, options, pixel);
    const Image image = b.renderFrame(1, options, quad);
    // A block's point per surface merges at most four pixels' points of that surface.
    EXPECT_GE(quad.shadedPoints * 4, pixel.shadedPoints);
    EXPECT_LT(quad.shadedPoints * 3, pixel.shadedPoints);
    // Coverage stays per sample: silhouettes as the reference's.
    EXPECT_LT(compareImages(image, ref).coverageDiff, 0.01);
    // Measured 23.7 dB (per pixel 30.7): at 120x80 the mortar lines are near a block wide.
    const double psnr = compareImages(image, ref).psnr;
    RecordProperty("quad_psnr", std::to_string(psnr));
    EXPECT_GT(psnr, 22.5);
    // A point's footprint is a whole pixel, twice the per-pixel one: a level coarser, so
    // about a quarter of the tiles.
    EXPECT_LT(quad.tiles.requested * 2, pixel.tiles.requested);
}

TEST(MultiphaseRenderer, WholePixelShortcutGivesTheSamePointsBitForBit) {
    // Odd sizes (blocks cut at the edges), several samples per pixel, both coarse rates.
    const Scene scene = loadScene(test::sourcePath("examples/gallery/scene.json"));
    for (const ShadingRate rate : {ShadingRate::Pixel, ShadingRate::Quad})
        for (const int spp : {1, 3, 4}) {
            RenderOptions options;
            options.width = 97, options.height = 55;
            options.samplesPerPixel = spp;
            MultiphaseOptions shortcut, general;
            shortcut.shadingRate = general.shadingRate = rate;
            shortcut.singlePhaseFrames = general.singlePhaseFrames = false;
            general.dynamic.wholePixelShortcut = false;
            MultiphaseRenderer a(scene, shortcut), b(scene, general);
            FrameStats sa, sb;
            const Image ia = a.renderFrame(2, options, sa);
            const Image ib = b.renderFrame(2, options, sb);
            ASSERT_EQ(ia.rgba.size(), ib.rgba.size());
            EXPECT_EQ(sa.shadedPoints, sb.shadedPoints);
            size_t differing = 0;
            for (size_t k = 0; k < ia.rgba.size(); ++k) differing += ia.rgba[k] != ib.rgba[k];
            EXPECT_EQ(differing, 0u) << shadingRateName(rate) << " spp " << spp;
        }
}

TEST(MultiphaseRenderer, MapsStayInTheirMemoryBudget) {
    // A budget far below what the courtyard's maps would take: tiles unused longest are
    // dropped (filled again when a frame needs them), the maps stay near the budget, and
    // the frames are as good as with room to spare.
    const Scene scene = loadScene(test::sourcePath("examples/courtyard/scene.json"));
    RenderOptions options;
    options.width = 96, options.height = 54;
    MultiphaseOptions tight, roomy;
    tight.mapMemoryBytes = size_t{1} << 20;
    MultiphaseRenderer a(scene, tight), b(scene, roomy);
    uint64_t evicted = 0;
    for (int frame = 0; frame < 40; frame += 8) {
        FrameStats sa, sb;
        const Image ia = a.renderFrame(frame, options, sa);
        const Image ib = b.renderFrame(frame, options, sb);
        evicted += sa.tiles.evicted;
        EXPECT_EQ(sb.tiles.evicted, 0u);
        // Over the budget only by the always-resident levels and what one frame needs.
        EXPECT_LT(sa.tiles.residentBytes, sb.tiles.residentBytes + 1u) << frame;
        EXPECT_GT(compareImages(ia, ib).psnr, 60.0) << frame;
    }
    EXPECT_GT(evicted, 0u);
}

}  // namespace
}  // namespace mpshade
