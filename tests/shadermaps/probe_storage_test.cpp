// Probes of half-precision shader maps: the AVX2 build (F16C conversions) and the portable
// one give the same bits (both convert exactly), and both stay within binary16's rounding of the
// float map's probes, on every filter and on the channel counts that take each path (3: one vector
// a texel, 5: two, 9: channel by channel).
#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "shadermaps/noise_maps.h"
#include "shadermaps/probe.h"
#include "shadermaps/probe_avx2.h"

namespace mpshade {
namespace {

// Queries spread over the chart with footprints from a tenth of a texel to most of the
// chart, isotropic and up to 30:1 in any direction, plus exact level sizes.
std::vector<ProbeQuery> spreadQueries() {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::vector<ProbeQuery> qs;
    for (int k = 0; k < 600; ++k) {
        ProbeQuery q;
        q.u = unit(rng), q.v = unit(rng);
        const float size = std::exp2(-12.0f + 11.0f * unit(rng));
        const float ratio = k % 3 == 0 ? 1.0f : 1.0f + 29.0f * unit(rng);
        const float angle = 6.2831853f * unit(rng);
        q.dudx = size * ratio * std::cos(angle), q.dvdx = size * ratio * std::sin(angle);
        q.dudy = -size * std::sin(angle), q.dvdy = size * std::cos(angle);
        qs.push_back(q);
    }
    for (int level = 0; level < 8; ++level) {
        ProbeQuery q;
        q.u = 0.3f, q.v = 0.6f;
        q.dudx = q.dvdy = std::exp2(static_cast<float>(level)) / 128.0f;
        qs.push_back(q);
    }
    return qs;
}

std::vector<ProbeOptions> everyFilter() {
    std::vector<ProbeOptions> filters(4);
    filters[0].filter = ProbeFilter::Trilinear;
    filters[1].filter = ProbeFilter::Feline;  // probe.h's defaults
    // The renderer's (dynamic_phase.h): one level mostly, 2:1, taps per unit of ratio.
    filters[2] = {ProbeFilter::Feline, 2.0f, 0.125f, 1.0f, AnisotropyCap::ShrinkMajor};
    filters[3].filter = ProbeFilter::EWA;
    return filters;
}

class HalfStorage : public ::testing::TestWithParam<int> {};

TEST_P(HalfStorage, Avx2AndPortableAgreeBitForBit) {
    if (!probeAvx2Available()) GTEST_SKIP() << "no AVX2 and F16C on this processor";
    const NoiseMaps maps(GetParam());
    const std::vector<ProbeQuery> qs = spreadQueries();
    const size_t values = qs.size() * static_cast<size_t>(GetParam());
    for (const ProbeOptions& o : everyFilter()) {
        std::vector<float> a(values), b(values);
        probeShaderMapAvx2(*maps.half, o, qs, ProbeOutput{a.data()}, nullptr);
        probeShaderMapPortable(*maps.half, o, qs, ProbeOutput{b.data()}, nullptr);
        for (size_t i = 0; i < values; ++i)
            ASSERT_EQ(a[i], b[i]) << "filter " << static_cast<int>(o.filter) << " value " << i;
    }
}

TEST_P(HalfStorage, WithinHalfRoundingOfTheFloatMap) {
    // Each texel is off by at most 2^-11 of its magnitude (half_float.h); a probe is a
    // convex combination of texels, so its error is at most 2^-11 times the largest
    // texel magnitude it read -- bounded here by the channel's scale, (1 + c).
    const int channels = GetParam();
    const NoiseMaps maps(channels);
    const std::vector<ProbeQuery> qs = spreadQueries();
    for (const ProbeOptions& o : everyFilter()) {
        std::vector<float> x(qs.size() * static_cast<size_t>(channels)), y(x.size());
        probeShaderMap(*maps.full, o, qs, x.data());
        probeShaderMap(*maps.half, o, qs, y.data());
        double worst = 0.0;
        for (size_t k = 0; k < qs.size(); ++k)
            for (int c = 0; c < channels; ++c) {
                const size_t i = k * static_cast<size_t>(channels) + static_cast<size_t>(c);
                const double bound = std::ldexp(1.0 + c, -11) * 1.0001 + 1e-6;
                worst = std::max(worst, std::fabs(x[i] - y[i]) / bound);
                ASSERT_LE(std::fabs(x[i] - y[i]), bound) << "filter " << static_cast<int>(o.filter)
                                                         << " query " << k << " channel " << c;
            }
        // Not identical either: the half map is read, rounded.
        EXPECT_GT(worst, 0.01) << "filter " << static_cast<int>(o.filter);
    }
}

TEST_P(HalfStorage, RowsPerChannelHoldWhatTheInterleavedLayoutHolds) {
    // The layout a shading batch reads: channel c of query k at rows[c][k], for float and
    // half maps and every filter; rows past the last query are not written.
    const int channels = GetParam();
    const NoiseMaps maps(channels);
    const std::vector<ProbeQuery> qs = spreadQueries();
    const size_t n = qs.size();
    for (const ShaderMap* map : {maps.full.get(), maps.half.get()})
        for (const ProbeOptions& o : everyFilter()) {
            std::vector<float> interleaved(n * static_cast<size_t>(channels));
            probeShaderMap(*map, o, qs, interleaved.data());
            std::vector<std::vector<float>> rows(static_cast<size_t>(channels),
                                                 std::vector<float>(n + 1, -7.0f));
            std::vector<float*> rowPointers;
            for (auto& r : rows) rowPointers.push_back(r.data());
            probeShaderMap(*map, o, qs, ProbeOutput{nullptr, rowPointers.data()});
            for (size_t k = 0; k < n; ++k)
                for (int c = 0; c < channels; ++c)
                    ASSERT_EQ(
                        rows[static_cast<size_t>(c)][k],
                        interleaved[k * static_cast<size_t>(channels) + static_cast<size_t>(c)])
                        << "filter " << static_cast<int>(o.filter) << " query " << k << " channel "
                        << c;
            for (const auto& r : rows) EXPECT_EQ(r[n], -7.0f);
        }
}

INSTANTIATE_TEST_SUITE_P(Channels, HalfStorage, ::testing::Values(3, 5, 9));

}  // namespace
}  // namespace mpshade
