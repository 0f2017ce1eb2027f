// The fixed-point warp (fixed_point_warp.h) against double precision over a range of
// views, and at extreme placements: no overflow, no crash, vertices culled or bounded.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "phases/fixed_point_warp.h"
#include "scene_fixtures.h"

namespace mpshade {
namespace {

using test::directionNear;
using test::lookAt;

TEST(FixedPointWarp, WithinASixteenthOfAPixelOverTheRange) {
    std::mt19937 rng(9);
    std::uniform_int_distribution<int> q(0, 65535);
    for (float scale : {1e-3f, 1.0f, 1e4f}) {
        Bounds3 b;
        b.extend(glm::vec3(-1.0f, -0.5f, -2.0f) * scale);
        b.extend(glm::vec3(1.5f, 2.0f, 1.0f) * scale);
        const FixedPointFormat format = FixedPointFormat::forBounds(b);
        const glm::vec3 center = b.center();
        const glm::vec3 repAxis = glm::normalize(glm::vec3(0.3f, 0.4f, 1.0f));
        const float repDistance = 4.0f * b.diagonal();
        double worst = 0.0;
        for (int view = 0; view < 200; ++view) {
            // Views within distance factor 2 and 20 degrees of the representative one.
            const float d =
                repDistance * std::exp2(std::uniform_real_distribution<float>(-1.0f, 1.0f)(rng));
            const glm::vec3 eye = center + d * directionNear(repAxis, 20.0f, rng);
            const glm::mat4 place =
                glm::translate(glm::mat4(1.0f), glm::vec3(0.25f * scale, 0.0f, 0.0f));
            const CameraState camera =
                lookAt(glm::vec3(place * glm::vec4(eye, 1.0f)),
                       glm::vec3(place * glm::vec4(center, 1.0f)), 640, 360, 40.0f, 1e-3f * scale);
            const FixedPointWarp warp(place, camera, format);
            EXPECT_LE(warp.errorBound(), 1.0 / 16.0) << "scale " << scale;
            double worstHere = 0.0;
            std::vector<uint16_t> x(500), y(500), z(500);
            for (size_t i = 0; i < x.size(); ++i)
                x[i] = uint16_t(q(rng)), y[i] = uint16_t(q(rng)), z[i] = uint16_t(q(rng));
            WarpedVertices out;
            warp.warp(x.data(), y.data(), z.data(), x.size(), out);
            for (size_t i = 0; i < x.size(); ++i) {
                double ex, ey;
                ASSERT_TRUE(warp.warpExact(x[i], y[i], z[i], ex, ey));
                ASSERT_FALSE(out.culled(i));
                worstHere = std::max({worstHere, std::fabs(out.x[i] / 256.0 - ex),
                                      std::fabs(out.y[i] / 256.0 - ey)});
            }
            // The bound is the warp's own promise, not only the 1/16 pixel target.
            EXPECT_LE(worstHere, warp.errorBound()) << "scale " << scale << " view " << view;
            worst = std::max(worst, worstHere);
        }
        EXPECT_LE(worst, 1.0 / 16.0) << "scale " << scale;
        RecordProperty("worst_warp_error_px_scale_" + std::to_string(scale), std::to_string(worst));
    }
}

TEST(FixedPointWarp, ExtremesNeitherOverflowNorCrash) {
    Bounds3 b;
    b.extend(glm::vec3(-1.0f));
    b.extend(glm::vec3(1.0f));
    const FixedPointFormat format = FixedPointFormat::forBounds(b);
    std::vector<uint16_t> x, y, z;
    for (int i = 0; i <= 16; ++i)
        for (int j = 0; j <= 16; ++j)
            for (int k = 0; k <= 16; ++k)
                x.push_back(uint16_t(std::min(65535, i * 4096))),
                    y.push_back(uint16_t(std::min(65535, j * 4096))),
                    z.push_back(uint16_t(std::min(65535, k * 4096)));
    struct Case {
        const char* what;
        glm::vec3 eye;
        float zNear;
    } cases[] = {
        {"camera inside the bounds", glm::vec3(0.1f, 0.2f, 0.3f), 0.01f},
        {"object across the near plane", glm::vec3(0, 0, 1.05f), 0.1f},
        {"far away", glm::vec3(0, 0, 1e6f), 0.1f},
        {"grazing, almost in the plane of a face", glm::vec3(30.0f, 1.0001f, 0.0f), 0.1f},
    };
    for (const Case& c : cases) {
        const CameraState camera =
            lookAt(c.eye, glm::vec3(0.0f, 0.0f, -0.5f), 320, 240, 60.0f, c.zNear);
        const FixedPointWarp warp(glm::mat4(1.0f), camera, format);
        WarpedVertices out;
        warp.warp(x.data(), y.data(), z.data(), x.size(), out);
        size_t kept = 0;
        for (size_t i = 0; i < x.size(); ++i) {
            ASSERT_TRUE(std::isfinite(out.invDepth[i])) << c.what;
            double ex, ey;
            const bool front = warp.warpExact(x[i], y[i], z[i], ex, ey);
            if (out.culled(i)) continue;
            ++kept;
            ASSERT_TRUE(front) << c.what;
            ASSERT_LE(out.invDepth[i], 1.0f / (c.zNear * 0.999f)) << c.what;
            // A kept vertex lies in the guard band and matches the exact projection.
            ASSERT_LT(std::fabs(ex), 32768.0) << c.what;
            ASSERT_NEAR(out.x[i] / 256.0, ex, 0.5) << c.what;
        }
        EXPECT_GT(kept, 0u) << c.what;
    }
}

}  // namespace
}  // namespace mpshade
