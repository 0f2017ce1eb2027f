#include "phases/split_verification.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "shading/shading_batch.h"

namespace mpshade {
namespace {

std::vector<int> spreadFrames(int count, int budget) {
    std::vector<int> frames;
    const int n = std::clamp(budget, 1, std::max(1, count));
    for (int k = 0; k < n; ++k) {
        const int f = n == 1 ? 0 : static_cast<int>(std::lround(double(k) * (count - 1) / (n - 1)));
        if (frames.empty() || frames.back() != f) frames.push_back(f);
    }
    return frames;
}

// Accumulates |a - b| for one output or channel.
struct Tally {
    SplitDifference d;
    double sumSquares = 0.0;
    size_t count = 0;

    void add(float a, float b, const SplitPoint& where) {
        const double diff = outputDifference(a, b), relative = relativeOutputDifference(a, b);
        if (count == 0 || diff > d.maxAbs) {
            d.maxAbs = diff;
            d.worst = where;
        }
        d.maxRelative = std::max(d.maxRelative, relative);
        sumSquares += std::isfinite(diff) ? diff * diff : 0.0;
        ++count;
    }
    SplitDifference result() {
        d.rms = count > 0 ? std::sqrt(sumSquares / static_cast<double>(count)) : 0.0;
        return d;
    }
};

}  // namespace

std::vector<ChartPoint> spreadChartPoints(const Surface& surface, int budget) {
    const int charts = chartCount(surface);
    std::vector<ChartPoint> points;
    if (charts <= 0) return points;
    const int k = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(budget) / charts)));
    const int stride = std::max(1, charts / std::max(1, budget));
    for (int c = 0; c < charts; c += stride)
        for (int j = 0; j < k; ++j)
            for (int i = 0; i < k; ++i)
                points.push_back(
                    {c, (i + 0.5f) / static_cast<float>(k), (j + 0.5f) / static_cast<float>(k)});
    return points;
}

double outputDifference(float a, float b) {
    if (std::isnan(a) && std::isnan(b)) return 0.0;
    if (!std::isfinite(a) || !std::isfinite(b)) return a == b ? 0.0 : INFINITY;
    return std::fabs(double(a) - double(b));
}

double relativeOutputDifference(float a, float b) {
    const double d = outputDifference(a, b);  // infinite: so is the relative difference
    return std::isfinite(d) ? d / std::max({std::fabs(double(a)), std::fabs(double(b)), 1.0}) : d;
}

double SplitVerification::maxRelative() const {
    double m = 0.0;
    for (const SplitDifference& d : outputs) m = std::max(m, d.maxRelative);
    return m;
}

SplitVerification verifySplit(const StaticPhase& statics, const SceneResources& resources,
                              size_t object, const SplitVerificationOptions& options) {
    const Scene& scene = resources.scene();
    const ObjectShading& obj = statics.shading(object);
    const Surface& surface = *scene.objects[object].surface;
    const std::vector<ChartPoint> at = spreadChartPoints(surface, options.points);
    const std::vector<int> frames = spreadFrames(scene.frameCount(), options.frames);
    const size_t n = at.size();
    const size_t channels = obj.factored.staticPart.channelOutputs.size();
    std::vector<SurfaceSample> geometry(n);
    for (size_t i = 0; i < n; ++i) geometry[i] = evaluate(surface, at[i]);

    const int width = scene.settings.width, height = scene.settings.height;
    const FrameState first = frameStateAt(resources, frames.front(), width, height, 1);
    ShadingBatch batch;
    batch.resize(n, channels);
    std::vector<float> workspace, stored(n * channels), whole(6 * n);
    ShadingCounters counters;

    std::vector<Tally> outputs(6), drift(channels);
    const char* names[6] = {"Ci[0]", "Ci[1]", "Ci[2]", "Oi[0]", "Oi[1]", "Oi[2]"};
    for (int k = 0; k < 6; ++k) outputs[static_cast<size_t>(k)].d.name = names[k];
    for (size_t c = 0; c < channels && c < obj.factored.channels.size(); ++c) {
        // The variable it holds, else the operation and where the source computes it.
        const ChannelInfo& info = obj.factored.channels[c];
        drift[c].d.name = !info.name.empty()
                              ? info.name
                              : "(" + std::string(opName(info.op)) + ") " +
                                    std::to_string(info.line) + ":" + std::to_string(info.column);
    }
    for (const int f : frames) {
        const FrameState state = frameStateAt(resources, f, width, height, 1);
        const ShadingUniforms& uniforms = state.uniforms[object];
        for (size_t i = 0; i < n; ++i) {
            const glm::vec3 d = geometry[i].P - state.objects[object].eye;
            const float len = glm::length(d);
            batch.setPoint(i, geometry[i], at[i], len > 0.0f ? d / len : glm::vec3(0, 0, 1));
        }
        // The whole shader at this frame.
        obj.directKernel->run(uniforms, batch.in, n, batch.out, workspace, counters);
        for (int k = 0; k < 3; ++k)
            for (size_t i = 0; i < n; ++i) {
                whole[static_cast<size_t>(k) * n + i] = batch.out.Ci[k][i];
                whole[static_cast<size_t>(3 + k) * n + i] = batch.out.Oi[k][i];
            }
        // The static part at this frame, then as the static run at the first frame left it.
        if (channels > 0) {
            obj.staticKernel->run(uniforms, batch.in, n, batch.out, workspace, counters);
            for (size_t c = 0; c < channels; ++c)
                std::copy(batch.channel(c), batch.channel(c) + n, stored.begin() + c * n);
            obj.staticKernel->run(first.uniforms[object], batch.in, n, batch.out, workspace,
                                  counters);
        }
        obj.dynamicKernel->run(uniforms, batch.in, n, batch.out, workspace, counters);
        for (size_t i = 0; i < n; ++i) {
            const SplitPoint where{f, at[i].chart, at[i].u, at[i].v};
            for (int k = 0; k < 3; ++k) {
                outputs[static_cast<size_t>(k)].add(batch.out.Ci[k][i],
                                                    whole[static_cast<size_t>(k) * n + i], where);
                outputs[static_cast<size_t>(3 + k)].add(
                    batch.out.Oi[k][i], whole[static_cast<size_t>(3 + k) * n + i], where);
            }
            for (size_t c = 0; c < channels; ++c)
                drift[c].add(batch.channel(c)[i], stored[c * n + i], where);
        }
    }
    SplitVerification v;
    v.points = static_cast<int>(n);
    v.frames = static_cast<int>(frames.size());
    for (Tally& t : outputs) v.outputs.push_back(t.result());
    for (Tally& t : drift) v.channels.push_back(t.result());
    return v;
}

}  // namespace mpshade
