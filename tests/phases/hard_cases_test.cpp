// The hard cases of examples/hard/ (README there): each rendered multi-phase at a small
// size against a truth (the reference at 32 samples, another seed), with the bound its
// README documents -- measured, less a margin, so a regression fails.
#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "controller/multiphase_renderer.h"
#include "phases/image_compare.h"
#include "phases/reference_renderer.h"
#include "test_support.h"

namespace mpshade {
namespace {

constexpr int kWidth = 128, kHeight = 72;

struct Measured {
    double multiphase = 0.0;  // PSNR against the truth, dB
    double reference = 0.0;   // the reference at the scene's spp, against the truth
    double coverage = 0.0;    // multi-phase's mean |alpha - truth's alpha|
    uint64_t nonFinite = 0;   // multi-phase's zeroed samples
    uint64_t referenceNonFinite = 0;
    bool finite = true;  // every pixel of the multi-phase image finite
    Image image;
    Representation firstObject = Representation::Auto;  // as last built
};

RenderOptions small() {
    RenderOptions o;
    o.width = kWidth, o.height = kHeight;
    return o;
}

// Multi-phase renders frames 0..frame in order (a render's history: every third of the
// way, or with `everyFrame` each one), then frame is measured.
Measured measure(const std::string& file, int frame, MultiphaseOptions options = {},
                 bool everyFrame = false) {
    const Scene scene = loadScene(test::sourcePath("examples/hard/" + file));
    options.singlePhaseFrames = false;  // the multi-phase path is what is judged
    MultiphaseRenderer multi(scene, options);
    ReferenceRenderer reference(scene);
    RenderOptions dense = small();
    dense.samplesPerPixel = 32;
    dense.seed = 0x9e3779b9u;
    FrameStats ts, rs, ms;
    const Image truth = reference.renderFrame(frame, dense, ts);
    const Image ref = reference.renderFrame(frame, small(), rs);
    Measured m;
    const int step = everyFrame ? 1 : std::max(1, frame / 3);
    for (int f = 0; f < frame; f += step) multi.renderFrame(f, small(), ms);
    m.image = multi.renderFrame(frame, small(), ms);
    if (const ObjectRepresentation* rep = multi.representation(0)) m.firstObject = rep->kind;
    const ImageError e = compareImages(m.image, truth);
    m.multiphase = e.psnr;
    m.coverage = e.coverageDiff;
    m.reference = compareImages(ref, truth).psnr;
    m.nonFinite = ms.nonFiniteSamples;
    m.referenceNonFinite = rs.nonFiniteSamples;
    for (float x : m.image.rgba) m.finite = m.finite && std::isfinite(x);
    ::testing::Test::RecordProperty(file + "_" + std::to_string(frame) + "_multiphase",
                                    std::to_string(m.multiphase));
    ::testing::Test::RecordProperty(file + "_" + std::to_string(frame) + "_reference",
                                    std::to_string(m.reference));
    std::printf(
        "%s frame %d: multi-phase %.2f dB, reference %.2f dB, coverage %.4f, "
        "non-finite %llu\n",
        file.c_str(), frame, m.multiphase, m.reference, m.coverage,
        static_cast<unsigned long long>(m.nonFinite));
    return m;
}

TEST(HardCases, GrazingFloorWithFineDetail) {
    // Kept a shader map: measured 1.6 and 2.0 dB better (the map prefilters the grout lines).
    MultiphaseOptions mapsKept;
    mapsKept.directWhenSlower = false;
    for (int frame : {0, 8}) {
        const Measured m = measure("grazing_floor.json", frame, mapsKept);
        EXPECT_TRUE(m.finite);
        EXPECT_EQ(m.firstObject, Representation::ShaderMap);
        EXPECT_GE(m.multiphase, m.reference + 0.5) << "frame " << frame;
    }
    // By default the floor's map, whose oblique footprints fill thousands of tiles a frame as
    // the camera dollies, measures slower than the reference would be within two frames, and
    // the floor goes direct: the whole shader per sample, as accurate as the reference
    // (measured equal to it at frame 8, 29.74 dB).
    const Measured first = measure("grazing_floor.json", 0);
    EXPECT_EQ(first.firstObject, Representation::ShaderMap);
    const Measured later = measure("grazing_floor.json", 8, {}, true);
    EXPECT_EQ(later.firstObject, Representation::Direct);
    EXPECT_TRUE(later.finite);
    EXPECT_GE(later.multiphase, later.reference - 0.5);
}

TEST(HardCases, MirrorLikeHighlightUnderAMovingLight) {
    for (int frame : {0, 6, 11}) {
        const Measured m = measure("mirror_highlight.json", frame);
        EXPECT_TRUE(m.finite);
        // Measured: 4.0 dB worse at frame 0, 0.7 worse and 0.9 better later: the highlight
        // reads normals interpolated over facets diced for a quarter pixel of geometric
        // error, and a 0.03-roughness lobe is narrower than their error (README).
        EXPECT_GE(m.multiphase, m.reference - 5.0) << "frame " << frame;
    }
}

TEST(HardCases, FastSpinningObject) {
    for (int frame : {1, 7}) {
        const Measured m = measure("fast_spin.json", frame);
        EXPECT_TRUE(m.finite);
        // Measured: 1.0 and 0.7 dB better.
        EXPECT_GE(m.multiphase, m.reference - 0.5) << "frame " << frame;
    }
}

TEST(HardCases, FineNoiseIsFilteredNotAliased) {
    for (int frame : {0, 9}) {
        const Measured m = measure("fine_noise.json", frame);
        EXPECT_TRUE(m.finite);
        // Measured: 4.2 dB better: the reference's 4 point samples alias the noise.
        EXPECT_GE(m.multiphase, m.reference + 2.0) << "frame " << frame;
    }
}

TEST(HardCases, ObjectCrossingTheNearPlane) {
    for (int frame : {0, 11}) {
        const Measured m = measure("near_plane.json", frame);
        EXPECT_TRUE(m.finite);
        EXPECT_LT(m.coverage, 0.01) << "frame " << frame;
        // Measured: 1.6 dB better at frame 0; 2.1 dB worse at frame 11, where the eye is
        // inside the ring's tube (both above 54 dB there).
        EXPECT_GE(m.multiphase, m.reference - 3.0) << "frame " << frame;
    }
}

TEST(HardCases, CameraInsideAnObjectsBounds) {
    for (int frame : {0, 11}) {
        const Measured m = measure("camera_inside.json", frame);
        EXPECT_TRUE(m.finite);
        EXPECT_LT(m.coverage, 0.01) << "frame " << frame;
        // Measured: 0.8 and 1.3 dB better.
        EXPECT_GE(m.multiphase, m.reference - 0.5) << "frame " << frame;
    }
}

TEST(HardCases, SubPixelObjects) {
    for (int frame : {0, 11}) {
        const Measured m = measure("subpixel.json", frame);
        EXPECT_TRUE(m.finite);
        // Measured: 1.9 and 2.0 dB better.
        EXPECT_GE(m.multiphase, m.reference) << "frame " << frame;
    }
}

TEST(HardCases, ShaderProducingNaNOnPartOfTheSurface) {
    const Measured m = measure("nan_shader.json", 4);
    EXPECT_TRUE(m.finite) << "NaN samples are zeroed, never written";
    EXPECT_GT(m.nonFinite, 0u) << "and counted";
    EXPECT_GT(m.referenceNonFinite, 0u);
    // Measured: 2.2 dB worse: a NaN texel spoils the probes whose footprint reaches it, so
    // the black region is about a texel wider than the reference's (README).
    EXPECT_GE(m.multiphase, m.reference - 3.0);
}

TEST(HardCases, TheSameSceneAtScales1e4And1e5MatchesScale1) {
    for (int frame : {0, 7}) {
        const Measured one = measure("scale_1.json", frame);
        for (const char* file : {"scale_1e-4.json", "scale_1e5.json"}) {
            const Measured other = measure(file, frame);
            EXPECT_TRUE(other.finite);
            const ImageError e = compareImages(other.image, one.image);
            std::printf("%s frame %d against scale 1: %.2f dB\n", file, frame, e.psnr);
            // Measured: identical images (99 dB): every step is relative to the scene's size.
            EXPECT_GE(e.psnr, 60.0) << file << " frame " << frame;
            EXPECT_LT(e.coverageDiff, 0.002) << file << " frame " << frame;
        }
    }
}

}  // namespace
}  // namespace mpshade
