// Feline probes of consecutive queries that share a setup go eight (or four) at a time in
// vector lanes (shadermaps/feline_lanes.h). Each query's answer must be the one it gets
// probed alone, bit for bit: the lanes do its arithmetic in the same order. Rows of
// queries a few texels apart cross tiles, reach a level's edges (where the one-at-a-time
// path clamps), and start where tiles are missing.
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "shadermaps/noise_maps.h"
#include "shadermaps/probe.h"
#include "shadermaps/probe_avx2.h"

namespace mpshade {
namespace {

// `count` queries along a line from (u, v), steps of `step` chart units jittered by up to a
// quarter of a step either way, all with one footprint (`size` chart units, `aniso`:1 at
// `angle`): what a facet's samples across a row of pixels ask.
std::vector<ProbeQuery> row(float u, float v, float stepU, float stepV, int count, float size,
                            float aniso, float angle, std::mt19937& rng) {
    std::uniform_real_distribution<float> jitter(-0.25f, 0.25f);
    const float c = std::cos(angle), s = std::sin(angle);
    std::vector<ProbeQuery> qs;
    for (int k = 0; k < count; ++k) {
        const float t = static_cast<float>(k) + jitter(rng);
        qs.push_back({0, u + t * stepU, v + t * stepV, size * aniso * c, size * aniso * s,
                      -size * s, size * c});
    }
    return qs;
}

// Rows over the chart at several footprints and directions, ending past its edges.
std::vector<std::vector<ProbeQuery>> rows() {
    std::mt19937 rng(11);
    std::vector<std::vector<ProbeQuery>> all;
    for (float size : {0.3f / 128.0f, 1.0f / 128.0f, 2.7f / 128.0f, 9.0f / 128.0f})
        for (float aniso : {1.0f, 1.6f, 3.0f})
            for (float angle : {0.0f, 0.7f, 2.2f}) {
                all.push_back(
                    row(0.01f, 0.37f, 0.6f / 128.0f, 0.05f / 128.0f, 220, size, aniso, angle, rng));
                all.push_back(
                    row(0.55f, 0.02f, 0.1f / 128.0f, 1.1f / 128.0f, 100, size, aniso, angle, rng));
                all.push_back(
                    row(0.1f, 0.1f, 2.5f / 128.0f, 2.4f / 128.0f, 60, size, aniso, angle, rng));
            }
    return all;
}

std::vector<ProbeOptions> felineOptions() {
    std::vector<ProbeOptions> options(3);
    options[0].filter = ProbeFilter::Feline;  // probe.h's defaults: two levels blended
    // The renderer's (dynamic_phase.h): one level mostly, 2:1, taps per unit of ratio.
    options[1] = {ProbeFilter::Feline, 2.0f, 0.125f, 1.0f, AnisotropyCap::ShrinkMajor};
    options[2] = {ProbeFilter::Feline, 8.0f, 0.5f, 2.0f, AnisotropyCap::ShrinkMajor};
    return options;
}

// Each query of `qs` probed in one batch against the same query probed alone.
void expectAloneEqualsBatch(const ShaderMap& map, const ProbeOptions& o,
                            const std::vector<ProbeQuery>& qs,
                            void (*probe)(const ShaderMap&, const ProbeOptions&,
                                          std::span<const ProbeQuery>, ProbeOutput,
                                          ProbeResidency*)) {
    const size_t channels = static_cast<size_t>(map.channels());
    std::vector<float> batch(qs.size() * channels), alone(channels);
    probe(map, o, qs, ProbeOutput{batch.data()}, nullptr);
    for (size_t k = 0; k < qs.size(); ++k) {
        probe(map, o, {&qs[k], 1}, ProbeOutput{alone.data()}, nullptr);
        for (size_t c = 0; c < channels; ++c)
            ASSERT_EQ(batch[k * channels + c], alone[c])
                << "query " << k << " (" << qs[k].u << ", " << qs[k].v << ") channel " << c;
    }
}

class ProbeLanes : public ::testing::TestWithParam<int> {};

TEST_P(ProbeLanes, EachQueryGetsWhatItGetsAlone) {
    const NoiseMaps maps(GetParam());
    for (const ShaderMap* map : {maps.full.get(), maps.half.get()})
        for (const ProbeOptions& o : felineOptions())
            for (const std::vector<ProbeQuery>& qs : rows()) {
                expectAloneEqualsBatch(*map, o, qs, probeShaderMapPortable);
                if (probeAvx2Available()) expectAloneEqualsBatch(*map, o, qs, probeShaderMapAvx2);
            }
}

// Charts with fewer texels along one axis (chart_aspect.h): 4 x 1 (v a quarter of u's) and
// 1 x 4 planes, where the lanes and the one-at-a-time path each scale u and v apart.
TEST_P(ProbeLanes, StretchedChartsGetWhatEachQueryGetsAlone) {
    for (Plane plane : {Plane{4.0f, 1.0f}, Plane{1.0f, 4.0f}}) {
        const NoiseMaps maps(GetParam(), plane);
        ASSERT_NE(maps.full->resolutionU(0, 0), maps.full->resolutionV(0, 0));
        for (const ProbeOptions& o : felineOptions())
            for (const std::vector<ProbeQuery>& qs : rows()) {
                expectAloneEqualsBatch(*maps.full, o, qs, probeShaderMapPortable);
                if (!probeAvx2Available()) continue;
                expectAloneEqualsBatch(*maps.full, o, qs, probeShaderMapAvx2);
                const size_t channels = static_cast<size_t>(GetParam());
                std::vector<float> a(qs.size() * channels), b(a.size());
                probeShaderMapAvx2(*maps.full, o, qs, ProbeOutput{a.data()}, nullptr);
                probeShaderMapPortable(*maps.full, o, qs, ProbeOutput{b.data()}, nullptr);
                ASSERT_EQ(0, std::memcmp(a.data(), b.data(), a.size() * sizeof(float)));
            }
    }
}

TEST_P(ProbeLanes, Avx2AndPortableAgreeOnRows) {
    if (!probeAvx2Available()) GTEST_SKIP() << "no AVX2 and F16C on this processor";
    const NoiseMaps maps(GetParam());
    const size_t channels = static_cast<size_t>(GetParam());
    for (const ProbeOptions& o : felineOptions())
        for (const std::vector<ProbeQuery>& qs : rows()) {
            std::vector<float> a(qs.size() * channels), b(a.size());
            probeShaderMapAvx2(*maps.full, o, qs, ProbeOutput{a.data()}, nullptr);
            probeShaderMapPortable(*maps.full, o, qs, ProbeOutput{b.data()}, nullptr);
            ASSERT_EQ(0, std::memcmp(a.data(), b.data(), a.size() * sizeof(float)));
        }
}

// Results written into channel rows (the lanes' go four queries at a time by a transpose)
// are the ones written query by query, in either build.
TEST_P(ProbeLanes, RowsHoldWhatInterleavedHolds) {
    const NoiseMaps maps(GetParam());
    const size_t channels = static_cast<size_t>(GetParam());
    using Probe = void (*)(const ShaderMap&, const ProbeOptions&, std::span<const ProbeQuery>,
                           ProbeOutput, ProbeResidency*);
    std::vector<Probe> builds = {probeShaderMapPortable};
    if (probeAvx2Available()) builds.push_back(probeShaderMapAvx2);
    for (Probe probe : builds)
        for (const ProbeOptions& o : felineOptions())
            for (const std::vector<ProbeQuery>& qs : rows()) {
                std::vector<float> interleaved(qs.size() * channels);
                std::vector<std::vector<float>> rowData(channels, std::vector<float>(qs.size()));
                std::vector<float*> rowPointers;
                for (std::vector<float>& r : rowData) rowPointers.push_back(r.data());
                probe(*maps.full, o, qs, ProbeOutput{interleaved.data()}, nullptr);
                probe(*maps.full, o, qs, ProbeOutput{nullptr, rowPointers.data()}, nullptr);
                for (size_t k = 0; k < qs.size(); ++k)
                    for (size_t c = 0; c < channels; ++c)
                        ASSERT_EQ(rowData[c][k], interleaved[k * channels + c])
                            << "query " << k << " channel " << c;
            }
}

// A map with most of its fine tiles missing: the lanes leave a query whose tiles are
// missing to the one-at-a-time path, so the answers (coarser levels' values), the counts
// and the queries marked as missing are what each query alone gives.
TEST_P(ProbeLanes, MissingTilesGoOneAtATime) {
    const NoiseMaps full(GetParam());
    ShaderMapOptions options;
    options.resolution = 128;
    options.alwaysResidentLevels = 2;
    ShaderMap map(full.surface, *full.kernel, ShadingUniforms{}, options);
    // Level 0's tiles of the left half of the chart, level 1's of its top half.
    std::vector<TileKey> some;
    for (int ty = 0; ty < 8; ++ty)
        for (int tx = 0; tx < 4; ++tx) some.push_back({0, 0, uint16_t(tx), uint16_t(ty)});
    for (int ty = 0; ty < 2; ++ty)
        for (int tx = 0; tx < 4; ++tx) some.push_back({0, 1, uint16_t(tx), uint16_t(ty)});
    map.fill(some);
    const size_t channels = static_cast<size_t>(GetParam());
    for (const ProbeOptions& o : felineOptions())
        for (const std::vector<ProbeQuery>& qs : rows())
            for (bool stop : {false, true}) {
                std::vector<TileKey> reported(4096);
                std::vector<uint8_t> missed(qs.size()), missedAlone(1);
                ProbeResidency batch{reported.data(), reported.size()};
                batch.stopAtMissing = stop;
                batch.queryMissed = missed.data();
                std::vector<float> a(qs.size() * channels), b(channels);
                probeShaderMap(map, o, qs, a.data(), &batch);
                ProbeResidency alone{reported.data(), reported.size()};
                alone.stopAtMissing = stop;
                alone.queryMissed = missedAlone.data();
                for (size_t k = 0; k < qs.size(); ++k) {
                    alone.count = 0;
                    probeShaderMap(map, o, {&qs[k], 1}, b.data(), &alone);
                    ASSERT_EQ(missed[k], missedAlone[0]) << "query " << k;
                    if (missed[k] && stop) continue;  // the result is meaningless
                    for (size_t c = 0; c < channels; ++c)
                        ASSERT_EQ(a[k * channels + c], b[c]) << "query " << k << " channel " << c;
                }
                EXPECT_EQ(batch.bilinearProbes, alone.bilinearProbes);
                EXPECT_EQ(batch.fallbacks, alone.fallbacks);
                EXPECT_EQ(batch.missingProbes, alone.missingProbes);
            }
}

// 3: one vector a texel; 5 and 8: two; 9: channel by channel, no lanes.
INSTANTIATE_TEST_SUITE_P(Channels, ProbeLanes, ::testing::Values(3, 5, 8, 9));

}  // namespace
}  // namespace mpshade
