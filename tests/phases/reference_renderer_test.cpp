// The reference renderer on cases with known answers: silhouette coverage of a sphere,
// front-to-back compositing of translucent layers, determinism, and non-finite shaders.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "phases/image_compare.h"
#include "phases/reference_renderer.h"
#include "scene/scene.h"
#include "test_support.h"

namespace mpshade {
namespace {

std::string writeScene(const std::string& name, const std::string& json,
                       const std::string& shader) {
    const std::string dir = ::testing::TempDir() + "mpshade_render_test_" + name + "/";
    std::filesystem::create_directories(dir);
    std::ofstream(dir + "s.sl") << shader;
    std::ofstream(dir + "scene.json") << json;
    return dir + "scene.json";
}

const char* kBallScene = R"({
  "settings": { "width": 96, "height": 96, "samples_per_pixel": 4, "background": [0, 0, 1] },
  "camera": { "fov_y": 40, "eye": [0, 0, 6], "target": [0, 0, 0] },
  "shaders": { "s": "s.sl" },
  "objects": [ { "name": "ball", "geometry": { "type": "sphere", "radius": 1 }, "shader": "s" } ]
})";

TEST(ReferenceRenderer, SphereCoverageMatchesItsSilhouette) {
    const Scene scene =
        loadScene(writeScene("coverage", kBallScene, "surface s() { Ci = color(1, 0, 0); }"));
    ReferenceRenderer renderer(scene);
    RenderOptions options;
    FrameStats stats;
    const SampleBuffer samples = renderer.renderSamples(0, options, stats);
    // The silhouette is a circle of angular radius asin(r / d) around the image centre.
    const float tanHalf = std::tan(20.0f * 3.14159265f / 180.0f);
    const float radiusPx = std::tan(std::asin(1.0f / 6.0f)) / tanHalf * 48.0f;
    int wrong = 0, boundary = 0;
    for (size_t i = 0; i < samples.layout->count(); ++i) {
        const float dx = samples.layout->x(i) - 48.0f, dy = samples.layout->y(i) - 48.0f;
        const float r = std::sqrt(dx * dx + dy * dy);
        const bool covered = samples.rgba[4 * i + 3] > 0.5f;
        if (std::fabs(r - radiusPx) < 0.05f) {
            ++boundary;
            continue;
        }
        if (covered != (r < radiusPx)) ++wrong;
        if (covered) {
            ASSERT_EQ(samples.rgba[4 * i + 0], 1.0f);
            ASSERT_EQ(samples.rgba[4 * i + 2], 0.0f);
        } else {
            ASSERT_EQ(samples.rgba[4 * i + 2], 1.0f);  // the background
        }
    }
    EXPECT_EQ(wrong, 0);
    EXPECT_LT(boundary, 200);
    EXPECT_EQ(stats.samples, 96u * 96u * 4u);
    EXPECT_EQ(stats.rays, stats.samples);
}

// Two parallel planes facing the camera, red in front of green, on blue; their shader
// sets the opacity.
const char* kTwoPlanesScene = R"({
  "settings": { "width": 16, "height": 16, "samples_per_pixel": 1, "background": [0, 0, 1] },
  "camera": { "fov_y": 30, "eye": [0, 5, 0], "target": [0, 0, 0], "up": [0, 0, -1] },
  "shaders": { "s": "s.sl" },
  "objects": [
    { "name": "front", "geometry": { "type": "plane", "size": [10, 10] }, "shader": "s",
      "params": { "c": [1, 0, 0] }, "transform": { "translate": [0, 1, 0] } },
    { "name": "back", "geometry": { "type": "plane", "size": [10, 10] }, "shader": "s",
      "params": { "c": [0, 1, 0] } } ]
})";

// Every pixel of `image` is `rgba` within 1e-5.
void expectEveryPixel(const Image& image, const float rgba[4]) {
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x)
            for (int c = 0; c < 4; ++c)
                ASSERT_NEAR(image.pixel(x, y)[c], rgba[c], 1e-5f)
                    << "pixel (" << x << ", " << y << ") channel " << c;
}

TEST(ReferenceRenderer, TranslucentLayersCompositeFrontToBack) {
    // Each plane Oi = 0.5.
    const Scene scene = loadScene(
        writeScene("layers", kTwoPlanesScene, "surface s(color c = 0) { Ci = c; Oi = 0.5; }"));
    ReferenceRenderer renderer(scene);
    FrameStats stats;
    const float expected[4] = {0.5f, 0.25f, 0.25f, 0.75f};
    expectEveryPixel(renderer.renderFrame(0, {}, stats), expected);
    EXPECT_EQ(stats.rays, 3u * 256u);  // each camera ray passes two layers and leaves
    EXPECT_EQ(stats.shadedPoints, 2u * 256u);
}

TEST(ReferenceRenderer, ColouredOpacityCompositesPerChannel) {
    // Oi = (0.5, 0.25, 1): each channel composites on its own. Red plane: C = (0.5, 0, 0),
    // T = (0.5, 0.75, 0); green behind adds 0.75 * 0.25 to green, T = (0.25, 0.5625, 0);
    // the blue background is hidden. Alpha is the mean coverage, 1 - (0.25 + 0.5625 + 0) / 3.
    const Scene scene =
        loadScene(writeScene("coloured", kTwoPlanesScene,
                             "surface s(color c = 0) { Ci = c; Oi = color(0.5, 0.25, 1.0); }"));
    FrameStats stats;
    const float expected[4] = {0.5f, 0.1875f, 0.0f, 1.0f - 0.8125f / 3.0f};
    expectEveryPixel(ReferenceRenderer(scene).renderFrame(0, {}, stats), expected);
    // Opacity over 1 counts as 1: the front plane alone, opaque.
    const Scene over = loadScene(
        writeScene("over_opaque", kTwoPlanesScene, "surface s(color c = 0) { Ci = c; Oi = 2.0; }"));
    const float opaque[4] = {1.0f, 0.0f, 0.0f, 1.0f};
    expectEveryPixel(ReferenceRenderer(over).renderFrame(0, {}, stats), opaque);
}

TEST(ImageCompare, ErrorsFromNumbersWorkedByHand) {
    // Two pixels: RGB differences (0.1, 0, 0) and (0, 0.2, 0) -- and 1.5 against 0.5, which
    // counts as 1 against 0.5 (clamped) -- so MSE = (0.01 + 0.04 + 0.25) / 6 = 0.05; alpha
    // differs by +0.25 and -0.25: a mean |difference| of 0.25, not 0.
    Image a(2, 1), b(2, 1);
    const float pa[8] = {0.6f, 0.3f, 0.2f, 1.0f, 0.4f, 0.7f, 0.5f, 0.5f};
    const float pb[8] = {0.5f, 0.3f, 0.2f, 0.75f, 0.4f, 0.5f, 0.5f, 0.75f};
    std::copy(pa, pa + 8, a.rgba.begin());
    std::copy(pb, pb + 8, b.rgba.begin());
    a.pixel(1, 0)[2] = 1.5f;
    b.pixel(1, 0)[2] = 0.5f;
    const ImageError e = compareImages(a, b);
    EXPECT_NEAR(e.rmse, std::sqrt(0.05), 1e-6);
    EXPECT_NEAR(e.psnr, 10.0 * std::log10(1.0 / 0.05), 1e-4);
    EXPECT_NEAR(e.maxAbs, 0.5, 1e-6);
    EXPECT_NEAR(e.coverageDiff, 0.25, 1e-6);
    EXPECT_EQ(compareImages(a, a).psnr, 99.0);
}

TEST(ReferenceRenderer, IsDeterministicForASeed) {
    const Scene scene = loadScene(test::sourcePath("examples/teapot/scene.json"));
    ReferenceRenderer renderer(scene);
    RenderOptions options;
    options.width = 80;
    options.height = 60;
    FrameStats s1, s2, s3;
    const Image a = renderer.renderFrame(3, options, s1);
    const Image b = renderer.renderFrame(3, options, s2);
    EXPECT_EQ(a.rgba, b.rgba);
    options.seed = 99;
    const Image c = renderer.renderFrame(3, options, s3);
    EXPECT_NE(a.rgba, c.rgba);
    EXPECT_EQ(s1.shaderInstructions, s2.shaderInstructions);
}

TEST(ReferenceRenderer, NonFiniteShaderResultsAreCountedAndZeroed) {
    const Scene scene = loadScene(writeScene(
        "nan", kBallScene, "surface s() { Ci = color(exp(1000 * u) - exp(1000 * u)); }"));
    ReferenceRenderer renderer(scene);
    FrameStats stats;
    const Image image = renderer.renderFrame(0, {}, stats);
    EXPECT_GT(stats.nonFiniteSamples, 0u);
    for (float v : image.rgba) ASSERT_TRUE(std::isfinite(v));
}

TEST(PixelFilter, PreservesAConstantImage) {
    const SampleLayout layout(7, 5, 3, 1u);
    std::vector<float> rgba(layout.count() * 4);
    for (size_t i = 0; i < layout.count(); ++i)
        for (int c = 0; c < 4; ++c) rgba[4 * i + c] = 0.25f * (c + 1);
    Image image;
    layout.resolve(rgba.data(), nullptr, image);
    for (int y = 0; y < 5; ++y)
        for (int x = 0; x < 7; ++x)
            for (int c = 0; c < 4; ++c) ASSERT_NEAR(image.pixel(x, y)[c], 0.25f * (c + 1), 1e-6f);
}

TEST(PixelFilter, MatchesTheTruncatedGaussianComputedDirectly) {
    // Radii whose reach (the pixels a sample can touch either side) differs: 1, 1 and 2.
    // One bright sample among dark ones: each pixel it reaches gets exactly its filter
    // weight over the pixel's total, computed here from the formula in double precision.
    const int w = 6, h = 5, spp = 2;
    std::vector<float> xy;
    for (int py = 0; py < h; ++py)
        for (int px = 0; px < w; ++px)
            for (int k = 0; k < spp; ++k)
                xy.push_back(px + 0.2f + 0.55f * k), xy.push_back(py + 0.7f - 0.45f * k);
    for (const float radius : {1.0f, 1.5f, 2.0f}) {
        SCOPED_TRACE(radius);
        const PixelFilter filter{radius, 0.5f};
        const SampleLayout layout(w, h, spp, xy, filter);
        const size_t bright = layout.index(2, 2, 1);
        std::vector<float> rgba(layout.count() * 4, 0.0f);
        rgba[4 * bright] = 1.0f;
        auto g = [&](double d) {
            const double s2 = 2.0 * 0.5 * 0.5;
            const double r = radius;
            return std::fabs(d) < r ? std::max(0.0, std::exp(-d * d / s2) - std::exp(-r * r / s2))
                                    : 0.0;
        };
        Image image;
        layout.resolve(rgba.data(), nullptr, image);
        for (int py = 0; py < h; ++py)
            for (int px = 0; px < w; ++px) {
                double total = 0.0, mine = 0.0;
                for (size_t s = 0; s < layout.count(); ++s) {
                    const double wgt = g(layout.x(s) - (px + 0.5)) * g(layout.y(s) - (py + 0.5));
                    total += wgt;
                    if (s == bright) mine = wgt;
                }
                EXPECT_NEAR(image.pixel(px, py)[0], mine / total, 1e-6) << px << "," << py;
            }
        // The bright sample at (2.75, 2.25) reaches the pixels around (2, 2) only; row 0's
        // centre is 1.75 away, two rows up: within reach of radius 2 only.
        EXPECT_GT(image.pixel(3, 1)[0], 0.0f);
        EXPECT_EQ(image.pixel(0, 2)[0], 0.0f);
        EXPECT_EQ(image.pixel(2, 4)[0], 0.0f);
        if (radius == 2.0f) {
            EXPECT_GT(image.pixel(2, 0)[0], 0.0f);
        }
    }
}

TEST(PixelFilter, UniformPixelsResolveAsTheirSamples) {
    // Marking pixels whose samples are alike must not change the image: the summed weights
    // stand in for the samples exactly.
    const SampleLayout layout(9, 7, 4, 5u);
    std::vector<float> rgba(layout.count() * 4);
    std::vector<uint8_t> uniform(9 * 7);
    for (int py = 0; py < 7; ++py)
        for (int px = 0; px < 9; ++px) {
            const bool alike = (px + py) % 3 != 0;
            uniform[static_cast<size_t>(py) * 9 + px] = alike ? 1 : 0;
            for (int k = 0; k < 4; ++k)
                for (int c = 0; c < 4; ++c)
                    rgba[4 * layout.index(px, py, k) + c] =
                        0.1f * c + 0.03f * px + 0.05f * py + (alike ? 0.0f : 0.07f * k);
        }
    Image a, b;
    layout.resolve(rgba.data(), nullptr, a);
    layout.resolve(rgba.data(), uniform.data(), b);
    for (size_t i = 0; i < a.rgba.size(); ++i) ASSERT_NEAR(a.rgba[i], b.rgba[i], 1e-6f);
}

TEST(PixelFilter, BlocksShadedOnceResolveAsTheirSamples) {
    // Shading once per 2x2 pixels: most blocks' four pixels hold one color and go to the
    // resolve as one; a block with one pixel of another color, or one pixel whose samples
    // differ, must not. Over three bands of rows (8 each) and odd sizes, so blocks meet
    // band edges and the image's last, partial, row and column.
    for (int spp : {1, 2}) {
        const int w = 21, h = 19;
        const SampleLayout layout(w, h, spp, 7u);
        std::vector<float> rgba(layout.count() * 4);
        std::vector<uint8_t> uniform(static_cast<size_t>(w) * h);
        for (int py = 0; py < h; ++py)
            for (int px = 0; px < w; ++px) {
                const int bx = px / 2, by = py / 2;
                const bool odd = (bx + 2 * by) % 5 == 0 && px % 2 == 1 && py % 2 == 0;
                const bool mixed = (bx + by) % 7 == 3 && px % 2 == 0 && py % 2 == 1;
                uniform[static_cast<size_t>(py) * w + px] = mixed ? 0 : 1;
                for (int k = 0; k < spp; ++k)
                    for (int c = 0; c < 4; ++c)
                        rgba[4 * layout.index(px, py, k) + c] = 0.1f * c + 0.05f * bx + 0.03f * by +
                                                                (odd ? 0.2f : 0.0f) +
                                                                (mixed ? 0.07f * (k + 1) : 0.0f);
            }
        Image a, b;
        layout.resolve(rgba.data(), nullptr, a);
        layout.resolve(rgba.data(), uniform.data(), b, true);
        for (size_t i = 0; i < a.rgba.size(); ++i)
            ASSERT_NEAR(a.rgba[i], b.rgba[i], 1e-6f) << spp << " spp, pixel " << i / 4;
    }
}

TEST(SamplePattern, CentroidsAndNearestSamplesOfPixelsAndQuads) {
    // Computed again here in double, by brute force.
    const SampleLayout layout(7, 5, 3, 11u);
    for (int py = 0; py < 5; ++py)
        for (int px = 0; px < 7; ++px) {
            const size_t pixel = static_cast<size_t>(py) * 7 + px;
            double cx = 0.0, cy = 0.0;
            for (int k = 0; k < 3; ++k) {
                cx += layout.x(layout.index(px, py, k)) / 3.0;
                cy += layout.y(layout.index(px, py, k)) / 3.0;
            }
            EXPECT_NEAR(layout.centroidX(pixel), cx, 1e-5);
            EXPECT_NEAR(layout.centroidY(pixel), cy, 1e-5);
            int nearest = 0;
            double best = 1e30;
            for (int k = 0; k < 3; ++k) {
                const double dx = layout.x(layout.index(px, py, k)) - cx,
                             dy = layout.y(layout.index(px, py, k)) - cy;
                if (dx * dx + dy * dy < best) best = dx * dx + dy * dy, nearest = k;
            }
            EXPECT_EQ(layout.nearestToCentroid(pixel), nearest) << px << " " << py;
        }
    for (int qy = 0; qy < 2; ++qy)  // 7x5: 3x2 whole blocks
        for (int qx = 0; qx < 3; ++qx) {
            const size_t block = static_cast<size_t>(qy) * 3 + qx;
            double cx = 0.0, cy = 0.0;
            std::vector<std::pair<double, double>> samples;
            for (int py = 2 * qy; py < 2 * qy + 2; ++py)
                for (int px = 2 * qx; px < 2 * qx + 2; ++px)
                    for (int k = 0; k < 3; ++k)
                        samples.push_back(
                            {layout.x(layout.index(px, py, k)), layout.y(layout.index(px, py, k))});
            for (const auto& [x, y] : samples) cx += x / 12.0, cy += y / 12.0;
            EXPECT_NEAR(layout.quadCentroidX(block), cx, 1e-5);
            EXPECT_NEAR(layout.quadCentroidY(block), cy, 1e-5);
            int nearest = 0;
            double best = 1e30;
            for (int m = 0; m < 12; ++m) {
                const double dx = samples[m].first - cx, dy = samples[m].second - cy;
                if (dx * dx + dy * dy < best) best = dx * dx + dy * dy, nearest = m;
            }
            EXPECT_EQ(layout.nearestToQuadCentroid(block), nearest) << qx << " " << qy;
        }
}

TEST(SamplePattern, StratifiesWithinThePixel) {
    for (int spp : {1, 4, 5, 16}) {
        for (int k = 0; k < spp; ++k) {
            float x, y;
            samplePosition(0, 3, 7, k, spp, x, y);
            EXPECT_GE(x, 3.0f);
            EXPECT_LT(x, 4.0f);
            EXPECT_GE(y, 7.0f);
            EXPECT_LT(y, 8.0f);
        }
    }
    // With 4 samples, one per quadrant.
    int quadrants = 0;
    for (int k = 0; k < 4; ++k) {
        float x, y;
        samplePosition(0, 0, 0, k, 4, x, y);
        quadrants |= 1 << ((x >= 0.5f) + 2 * (y >= 0.5f));
    }
    EXPECT_EQ(quadrants, 15);
}

}  // namespace
}  // namespace mpshade
