#include "shading/shader_harness.h"

namespace mpshade::test {

ShadingResult runKernel(const ShaderKernel& kernel, const std::vector<ShadingPoint>& points,
                        const ShadingUniforms& uniforms,
                        const std::vector<std::vector<float>>* channelsIn,
                        std::vector<std::vector<float>>* channelsOut) {
    const size_t n = points.size();
    std::vector<std::vector<float>> rows(28, std::vector<float>(n));
    for (size_t i = 0; i < n; ++i) {
        const ShadingPoint& p = points[i];
        for (int k = 0; k < 3; ++k) {
            rows[0 + k][i] = p.P[k];
            rows[3 + k][i] = p.N[k];
            rows[6 + k][i] = p.Ng[k];
            rows[9 + k][i] = p.dPdu[k];
            rows[12 + k][i] = p.dPdv[k];
            rows[15 + k][i] = p.I[k];
        }
        rows[18][i] = p.u, rows[19][i] = p.v, rows[20][i] = p.s, rows[21][i] = p.t;
    }
    ShadingInputs in;
    for (int k = 0; k < 3; ++k) {
        in.P[k] = rows[0 + k].data();
        in.N[k] = rows[3 + k].data();
        in.Ng[k] = rows[6 + k].data();
        in.dPdu[k] = rows[9 + k].data();
        in.dPdv[k] = rows[12 + k].data();
        in.I[k] = rows[15 + k].data();
    }
    in.u = rows[18].data(), in.v = rows[19].data(), in.s = rows[20].data(), in.t = rows[21].data();
    std::vector<const float*> inChannels;
    if (channelsIn)
        for (const auto& c : *channelsIn) inChannels.push_back(c.data());
    in.channels = inChannels.data();
    ShadingOutputs out;
    for (int k = 0; k < 3; ++k) out.Ci[k] = rows[22 + k].data(), out.Oi[k] = rows[25 + k].data();
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
        result.Ci.emplace_back(rows[22][i], rows[23][i], rows[24][i]);
        result.Oi.emplace_back(rows[25][i], rows[26][i], rows[27][i]);
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
