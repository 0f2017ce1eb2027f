// noise_maps.h -- a float and a half-precision shader map of `channels` noise values (the
// static part of a test shader, stored however cheap), over a 4 x 4 plane (or the plane
// given: a 4 x 1 one has a quarter of the texels along v, chart_aspect.h), every level
// filled: what the probe tests read.
#pragma once

#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "shadermaps/shader_map.h"
#include "shading/factoring.h"
#include "shading/shader_compiler.h"

namespace mpshade {

struct NoiseMaps {
    Surface surface = Plane{4.0f, 4.0f};
    FactoredShader factored;
    std::unique_ptr<ShaderKernel> kernel;
    std::unique_ptr<ShaderMap> full, half;

    explicit NoiseMaps(int channels, Plane plane = Plane{4.0f, 4.0f}) : surface(plane) {
        std::string body;
        for (int c = 0; c < channels; ++c)
            body += "  float a" + std::to_string(c) + " = noise(P * " + std::to_string(3 + c) +
                    ") * " + std::to_string(1 + c) + ";\n";
        std::string sum = "a0";
        for (int c = 1; c < channels; ++c) sum += " * (1 + time) + a" + std::to_string(c);
        const std::string source =
            "surface s() {\n" + body + "  Ci = color(" + sum + " * (1 + time));\n}\n";
        auto ast = compileShaderText("storage.sl", source);
        FactorOptions store;
        store.storeAboveCost = 0;
        factored = factorShader(*ast, {}, store);
        kernel = std::make_unique<ShaderKernel>(factored.staticPart);
        ShaderMapOptions options;
        options.resolution = 128;
        full = std::make_unique<ShaderMap>(surface, *kernel, ShadingUniforms{}, options);
        options.halfPrecision = true;
        half = std::make_unique<ShaderMap>(surface, *kernel, ShadingUniforms{}, options);
        full->fillLevels(0, full->levels() - 1);
        half->fillLevels(0, half->levels() - 1);
        EXPECT_EQ(full->channels(), channels);
    }
};

}  // namespace mpshade
