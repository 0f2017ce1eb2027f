#include "controller/stage_limits.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <functional>
#include <memory>

#include <tbb/parallel_for.h>

#include "phases/worker_threads.h"

namespace mpshade {
namespace {

// What each stage moves through memory at least, bytes: per vertex warped, 6 of quantized
// position read and 16 of screen position, depth and flags written; per sample, the
// rasterizer's 8 of fixed-point position read and 13 of visibility (depth, object, facet,
// count) written; shading reads the visibility and writes 16 of RGBA, and per shading point
// writes and reads back 40 (object, facet, x, y, color, opacity); the resolve reads 16 of
// RGBA and 24 of filter weights per sample and writes 16 of RGBA per pixel, reading its
// inverse weight sum.
constexpr double kWarpBytesPerVertex = 6.0 + 16.0;
constexpr double kRasterBytesPerSample = 8.0 + 13.0;
constexpr double kShadeBytesPerSample = 13.0 + 16.0;
constexpr double kShadeBytesPerPoint = 2.0 * 40.0;
constexpr double kResolveBytesPerSample = 16.0 + 24.0;
constexpr double kResolveBytesPerPixel = 16.0 + 4.0;

double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

MachineLimits measureMachineLimits() {
    MachineLimits m;
    m.cores = workerThreads();
    constexpr size_t kBytes = size_t{64} << 20;
    const std::unique_ptr<char[]> from(new char[kBytes]), to(new char[kBytes]);
    std::memset(from.get(), 1, kBytes);
    std::memset(to.get(), 0, kBytes);
    const size_t chunk = kBytes / static_cast<size_t>(m.cores);
    double best = 0.0;
    for (int round = 0; round < 3; ++round) {
        const auto start = std::chrono::steady_clock::now();
        tbb::parallel_for(0, m.cores, [&](int c) {
            const size_t at = static_cast<size_t>(c) * chunk;
            std::memcpy(to.get() + at, from.get() + at, chunk);
        });
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (seconds > 0.0) best = std::max(best, 2.0 * static_cast<double>(kBytes) / seconds);
    }
    m.bytesPerSecond = best;
    return m;
}

std::vector<StageCost> dynamicStageCosts(const std::vector<FrameStats>& frames, int spp,
                                         const MachineLimits& machine) {
    std::vector<const FrameStats*> steady, multiphase;
    for (const FrameStats& f : frames) {
        if (f.singlePhase || f.samples == 0) continue;
        multiphase.push_back(&f);
        if (f.staticWork.work.runs == 0) steady.push_back(&f);
    }
    if (steady.empty() && multiphase.size() > 1)
        steady.assign(multiphase.begin() + 1, multiphase.end());
    if (steady.empty()) steady = multiphase;
    if (steady.empty()) return {};
    const double cores = machine.cores;
    const double perPixel = 1.0 / std::max(1, spp);
    struct Stage {
        const char* name;
        std::function<double(const FrameStats&)> seconds, bytesPerSample, instructionsPerSample;
    };
    auto per = [](double count, const FrameStats& f) {
        return count / static_cast<double>(f.samples);
    };
    const Stage stages[] = {
        {"warp", [](const FrameStats& f) { return f.dynamic.warpSeconds; },
         [&](const FrameStats& f) {
             return per(kWarpBytesPerVertex * static_cast<double>(f.dynamic.verticesWarped), f);
         },
         nullptr},
        {"rasterize", [](const FrameStats& f) { return f.dynamic.rasterSeconds; },
         [](const FrameStats&) { return kRasterBytesPerSample; }, nullptr},
        {"shade", [](const FrameStats& f) { return f.dynamic.shadeSeconds; },
         [&](const FrameStats& f) {
             return kShadeBytesPerSample +
                    per(kShadeBytesPerPoint * static_cast<double>(f.dynamic.shadingPoints), f);
         },
         [&](const FrameStats& f) { return per(static_cast<double>(f.dynamic.instructions), f); }},
        {"resolve", [](const FrameStats& f) { return f.dynamic.resolveSeconds; },
         [&](const FrameStats&) {
             return kResolveBytesPerSample + perPixel * kResolveBytesPerPixel;
         },
         nullptr},
    };
    // Shade's parts: thread-summed CPU seconds, so not multiplied by the cores.
    using Parts = DynamicFrameStats::ShadeParts;
    const std::pair<const char*, double Parts::*> partFields[] = {
        {"points", &Parts::points},
        {"interpolate", &Parts::interpolate},
        {"probe", &Parts::probe},
        {"kernel", &Parts::kernel},
        {"composite", &Parts::composite}};
    auto shadeParts = [&](double shadeNs) {
        std::vector<StageCost> parts;
        double sum = 0.0;
        for (const auto& [name, field] : partFields) {
            std::vector<double> ns;
            for (const FrameStats* f : steady)
                ns.push_back(1e9 * f->dynamic.shadeParts.*field / static_cast<double>(f->samples));
            StageCost c{name, true};
            c.nsPerSample = median(ns);
            if (field == &Parts::kernel) {
                std::vector<double> instructions;
                for (const FrameStats* f : steady)
                    instructions.push_back(per(static_cast<double>(f->dynamic.instructions), *f));
                c.instructionsPerSample = median(instructions);
            }
            sum += c.nsPerSample;
            parts.push_back(c);
        }
        StageCost other{"other", true};
        other.nsPerSample = std::max(0.0, shadeNs - sum);
        parts.push_back(other);
        return parts;
    };
    std::vector<StageCost> out;
    StageCost total{"dynamic phase"};
    for (const Stage& stage : stages) {
        std::vector<double> ns, bytes, instructions;
        for (const FrameStats* f : steady) {
            ns.push_back(1e9 * stage.seconds(*f) * cores / static_cast<double>(f->samples));
            bytes.push_back(stage.bytesPerSample(*f));
            if (stage.instructionsPerSample)
                instructions.push_back(stage.instructionsPerSample(*f));
        }
        StageCost c{stage.name};
        c.nsPerSample = median(ns);
        c.bytesPerSample = median(bytes);
        c.boundNsPerSample = machine.bytesPerSecond > 0.0
                                 ? 1e9 * c.bytesPerSample * cores / machine.bytesPerSecond
                                 : 0.0;
        c.instructionsPerSample = median(instructions);
        total.nsPerSample += c.nsPerSample;
        total.bytesPerSample += c.bytesPerSample;
        total.boundNsPerSample += c.boundNsPerSample;
        total.instructionsPerSample += c.instructionsPerSample;
        out.push_back(c);
        if (c.name == "shade")
            for (const StageCost& part : shadeParts(c.nsPerSample)) out.push_back(part);
    }
    out.push_back(total);
    return out;
}

}  // namespace mpshade
