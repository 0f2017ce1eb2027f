#include "shading/shader_harness.h"

#include "shading/shading_batch.h"

namespace mpshade::test {

ShadingResult runKernel(const ShaderKernel& kernel, const std::vector<ShadingPoint>& points,
                        const ShadingUniforms& uniforms,
                        const std::vector<std::vector<float>>* channelsIn,
                        std::vector<std::vector<float>>* channelsOut) {
    const size_t n = points.size();
    ShadingBatch batch;
    batch.resize(n, 0);
    for (size_t i = 0; i < n; ++i) {
        const ShadingPoint& p = points[i];
        SurfaceSample g;
        g.P = p.P, g.N = p.N, g.Ng = p.Ng, g.dPdu = p.dPdu, g.dPdv = p.dPdv, g.s = p.s, g.t = p.t;
        batch.setPoint(i, g, {0, p.u, p.v}, p.I);
    }
    ShadingInputs& in = batch.in;
    ShadingOutputs& out = batch.out;
    std::vector<const float*> inChannels;
    if (channelsIn)
        for (const auto& c : *channelsIn) inChannels.push_back(c.data());
    in.channels = inChannels.data();
    std::vector<float*> outChannels;
    if (channelsOut) {
        channelsOut->assign(kernel.program().channelOutputs.size(), std::vector<float>(n));
        for (auto& c : *channelsOut) outChannels.push_back(c.data());
    }
    out.channels = outChannels.data();
    ShadingResult result;
    std::vector<float> workspace;
    kernel.run(uniforms, in, n, out, workspace, result.counters);
    for (size_t i = 0; i < n; ++i) {
        result.Ci.emplace_back(out.Ci[0][i], out.Ci[1][i], out.Ci[2][i]);
        result.Oi.emplace_back(out.Oi[0][i], out.Oi[1][i], out.Oi[2][i]);
    }
    return result;
}

ShadingResult runShader(const std::string& source, const std::vector<ShadingPoint>& points,
                        const ShaderBinding& binding, const ShadingUniforms& uniforms) {
    auto ast = compileShaderText("test.sl", source);
    auto kernel = buildKernel(*ast, binding);
    return runKernel(*kernel, points, uniforms);
}

}  // namespace mpshade::test
