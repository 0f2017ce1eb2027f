// The resolve's AVX-512 build against its baseline build (phases/resolve_rows.h): the same
// bits on every path a pixel can take. Its weights against independent numbers are in
// reference_renderer_test.cpp (PixelFilter).
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "phases/resolve_builds.h"
#include "phases/sample_pattern.h"

namespace mpshade {
namespace {

// Per-sample RGBA over a w x h layout: alike pixels (every sample one value, marked in
// `uniform`), alike 2x2 blocks and pixels whose samples differ.
std::vector<float> testSamples(const SampleLayout& layout, int w, int h, int spp,
                               std::vector<uint8_t>& uniform) {
    std::mt19937 random(17);
    std::uniform_real_distribution<float> value(-2.0f, 40.0f);
    std::vector<float> rgba(layout.count() * 4);
    uniform.assign(static_cast<size_t>(w) * h, 0);
    for (int py = 0; py < h; ++py)
        for (int px = 0; px < w; ++px) {
            const bool alike = (px * 7 + py * 3) % 5 != 0;
            uniform[static_cast<size_t>(py) * w + px] = alike ? 1 : 0;
            float block[4];
            std::mt19937 blockRandom(static_cast<uint32_t>((py / 2) * 100 + px / 2));
            for (float& c : block) c = value(blockRandom);
            for (int k = 0; k < spp; ++k)
                for (int c = 0; c < 4; ++c)
                    rgba[4 * layout.index(px, py, k) + c] =
                        alike && (px + py) % 4 != 1 ? block[c] : value(random);
        }
    return rgba;
}

// The marks made honest: a marked pixel's samples hold its first's value.
void copyMarkedSamples(std::vector<float>& rgba, const uint8_t* marks, int pixels, int spp) {
    if (!marks) return;
    for (int p = 0; p < pixels; ++p)
        if (marks[p])
            for (int k = 1; k < spp; ++k)
                std::memcpy(&rgba[4 * (static_cast<size_t>(p) * spp + k)],
                            &rgba[4 * static_cast<size_t>(p) * spp], 16);
}

TEST(Resolve, RectanglesGetTheWholeImagesBitsAndTheRestIsLeft) {
    // Rectangles at the image's corners and edges, from odd and even columns, one pixel
    // and wide, through alike 2x2 blocks and pixels whose samples differ: each pixel in
    // them the bits the whole image's resolve gives it, every pixel outside untouched.
    const int w = 23, h = 19;
    const std::vector<PixelRect> rects = {{0, 0, 1, 1},    {22, 18, 23, 19}, {3, 2, 10, 9},
                                          {10, 9, 23, 12}, {0, 12, 5, 19},   {1, 1, 2, 2},
                                          {6, 13, 22, 18}, {11, 0, 23, 1},   {7, 18, 8, 19}};
    constexpr float kUntouched = 1234.5f;
    for (const float radius : {1.5f, 2.5f})
        for (int spp = 1; spp <= 4; ++spp)
            for (const bool quads : {false, true})
                for (const ResolveBuild build : {ResolveBuild::Fastest, ResolveBuild::Portable}) {
                    SCOPED_TRACE(testing::Message()
                                 << "radius " << radius << ", " << spp << " spp, quads " << quads
                                 << ", build " << static_cast<int>(build));
                    const SampleLayout layout(w, h, spp, 3u, PixelFilter{radius, 0.5f});
                    std::vector<uint8_t> uniform;
                    std::vector<float> rgba = testSamples(layout, w, h, spp, uniform);
                    for (const uint8_t* marks : {static_cast<const uint8_t*>(nullptr),
                                                 static_cast<const uint8_t*>(uniform.data())}) {
                        copyMarkedSamples(rgba, marks, w * h, spp);
                        Image whole, parts(w, h);
                        layout.resolve(rgba.data(), marks, whole, quads, build);
                        std::fill(parts.rgba.begin(), parts.rgba.end(), kUntouched);
                        layout.resolveRects(rgba.data(), marks, parts, rects, quads, build);
                        for (int y = 0; y < h; ++y)
                            for (int x = 0; x < w; ++x) {
                                bool inside = false;
                                for (const PixelRect& r : rects)
                                    inside =
                                        inside || (x >= r.x0 && x < r.x1 && y >= r.y0 && y < r.y1);
                                for (int c = 0; c < 4; ++c) {
                                    const float want = inside ? whole.pixel(x, y)[c] : kUntouched;
                                    ASSERT_EQ(std::memcmp(&parts.pixel(x, y)[c], &want, 4), 0)
                                        << x << ", " << y << " channel " << c;
                                }
                            }
                    }
                }
}

TEST(Resolve, ThePixelsReadingChangedOnesAreThoseWithinTheFiltersReach) {
    // Random changed rectangles (touching, overlapping, at the edges): the rectangles
    // returned cover each pixel within the filter's reach of a changed pixel exactly once
    // (the Chebyshev distance: a pixel reads the samples of the pixels that far), and no
    // other. Radius 1.5 reaches one pixel, 2.5 two.
    const int w = 31, h = 27;
    std::mt19937 random(5);
    for (const float radius : {1.5f, 2.5f}) {
        const int reach = radius < 2.0f ? 1 : 2;
        const SampleLayout layout(w, h, 1, 3u, PixelFilter{radius, 0.5f});
        for (int trial = 0; trial < 20; ++trial) {
            std::vector<PixelRect> changed;
            for (int k = 0; k < 1 + trial % 6; ++k) {
                const int x0 = static_cast<int>(random() % w), y0 = static_cast<int>(random() % h);
                changed.push_back({x0, y0, std::min(w, x0 + 1 + static_cast<int>(random() % 9)),
                                   std::min(h, y0 + 1 + static_cast<int>(random() % 9))});
            }
            std::vector<int> covered(static_cast<size_t>(w) * h, 0);
            for (const PixelRect& r : layout.pixelsReading(changed)) {
                ASSERT_TRUE(r.x0 >= 0 && r.x0 < r.x1 && r.x1 <= w && r.y0 >= 0 && r.y0 < r.y1 &&
                            r.y1 <= h);
                for (int y = r.y0; y < r.y1; ++y)
                    for (int x = r.x0; x < r.x1; ++x) ++covered[static_cast<size_t>(y) * w + x];
            }
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    bool near = false;
                    for (const PixelRect& r : changed)
                        near = near || (x >= r.x0 - reach && x < r.x1 + reach &&
                                        y >= r.y0 - reach && y < r.y1 + reach);
                    ASSERT_EQ(covered[static_cast<size_t>(y) * w + x], near ? 1 : 0)
                        << "radius " << radius << ", trial " << trial << ", pixel " << x << ", "
                        << y;
                }
        }
    }
}

TEST(Resolve, EveryBuildAgreesWithThePortableOneBitForBit) {
    // Sizes over several bands of 8 rows with odd last rows and columns; 1-4 samples a
    // pixel; filters reaching one pixel (the 3x3 paths) and two (the general path).
    int builds = 0;
    for (const ResolveBuild build : {ResolveBuild::Avx2, ResolveBuild::Avx512}) {
        if (!resolveBuildAvailable(build)) continue;
        ++builds;
        for (const float radius : {1.5f, 2.5f})
            for (int spp = 1; spp <= 4; ++spp)
                for (const bool quads : {false, true}) {
                    SCOPED_TRACE(testing::Message()
                                 << "build " << static_cast<int>(build) << ", radius " << radius
                                 << ", " << spp << " spp, quads " << quads);
                    const int w = 23, h = 19;
                    const SampleLayout layout(w, h, spp, 3u, PixelFilter{radius, 0.5f});
                    std::vector<uint8_t> uniform;
                    std::vector<float> rgba = testSamples(layout, w, h, spp, uniform);
                    for (const uint8_t* marks : {static_cast<const uint8_t*>(nullptr),
                                                 static_cast<const uint8_t*>(uniform.data())}) {
                        copyMarkedSamples(rgba, marks, w * h, spp);
                        Image fast, portable;
                        layout.resolve(rgba.data(), marks, fast, quads, build);
                        layout.resolve(rgba.data(), marks, portable, quads, ResolveBuild::Portable);
                        ASSERT_EQ(fast.rgba.size(), portable.rgba.size());
                        EXPECT_EQ(std::memcmp(fast.rgba.data(), portable.rgba.data(),
                                              fast.rgba.size() * sizeof(float)),
                                  0);
                    }
                }
    }
    if (builds == 0) GTEST_SKIP() << "no AVX2 or AVX-512 on this processor";
}

}  // namespace
}  // namespace mpshade
