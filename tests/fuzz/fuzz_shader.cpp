// Fuzz target: the shading language front end -- lexer, parser, type checker, lowering,
// factoring -- and a run of both factored parts on a few points. Any text must compile or
// throw InputError.
#include <cstddef>
#include <cstdint>
#include <string>

#include "geometry/error.h"
#include "shading/factoring.h"
#include "shading/lower.h"
#include "shading/shader_compiler.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        auto ast = mpshade::compileShaderText("fuzz.sl", text);
        mpshade::lowerShader(*ast, {});
        mpshade::factorShader(*ast, {});
    } catch (const mpshade::InputError&) {
    }
    return 0;
}
