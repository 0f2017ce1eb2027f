// The resolve's AVX-512 build against its baseline build (phases/resolve_rows.h): the same
// bits on every path a pixel can take. Its weights against independent numbers are in
// reference_renderer_test.cpp (PixelFilter).
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "phases/resolve_avx512.h"
#include "phases/sample_pattern.h"

namespace mpshade {
namespace {

TEST(Resolve, Avx512AndPortableBuildsAgreeBitForBit) {
    if (!resolveAvx512Available()) GTEST_SKIP() << "no AVX-512 on this processor";
    std::mt19937 random(17);
    std::uniform_real_distribution<float> value(-2.0f, 40.0f);
    // Sizes over several bands of 8 rows with odd last rows and columns; 1-4 samples a
    // pixel; filters reaching one pixel (the 3x3 paths) and two (the general path).
    for (const float radius : {1.5f, 2.5f})
        for (int spp = 1; spp <= 4; ++spp)
            for (const bool quads : {false, true}) {
                SCOPED_TRACE(testing::Message()
                             << "radius " << radius << ", " << spp << " spp, quads " << quads);
                const int w = 23, h = 19;
                const SampleLayout layout(w, h, spp, 3u, PixelFilter{radius, 0.5f});
                std::vector<float> rgba(layout.count() * 4);
                std::vector<uint8_t> uniform(static_cast<size_t>(w) * h);
                for (int py = 0; py < h; ++py)
                    for (int px = 0; px < w; ++px) {
                        // Alike pixels, alike 2x2 blocks and pixels whose samples differ.
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
                for (const uint8_t* marks : {static_cast<const uint8_t*>(nullptr),
                                             static_cast<const uint8_t*>(uniform.data())}) {
                    // The marks are honest: a marked pixel's samples hold its first's value.
                    if (marks)
                        for (int p = 0; p < w * h; ++p)
                            if (marks[p])
                                for (int k = 1; k < spp; ++k)
                                    std::memcpy(&rgba[4 * (static_cast<size_t>(p) * spp + k)],
                                                &rgba[4 * static_cast<size_t>(p) * spp], 16);
                    Image fast, portable;
                    layout.resolve(rgba.data(), marks, fast, quads, ResolveBuild::Fastest);
                    layout.resolve(rgba.data(), marks, portable, quads, ResolveBuild::Portable);
                    ASSERT_EQ(fast.rgba.size(), portable.rgba.size());
                    EXPECT_EQ(std::memcmp(fast.rgba.data(), portable.rgba.data(),
                                          fast.rgba.size() * sizeof(float)),
                              0);
                }
            }
}

}  // namespace
}  // namespace mpshade
