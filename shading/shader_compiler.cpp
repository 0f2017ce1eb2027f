#include "shading/shader_compiler.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "geometry/error.h"
#include "shading/lower.h"
#include "shading/parser.h"
#include "shading/typecheck.h"

namespace mpshade {

std::shared_ptr<const ShaderAst> compileShaderText(const std::string& file,
                                                   const std::string& text) {
    auto ast = std::make_shared<ShaderAst>(parseShader(file, text));
    ast->source = text;
    typecheckShader(*ast);
    return ast;
}

std::shared_ptr<const ShaderAst> loadShaderFile(const std::string& path) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
        throw InputError({path, 0, 0, {}}, "is a folder, not a shader file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError({path, 0, 0, {}}, "cannot open shader file");
    std::ostringstream text;
    text << in.rdbuf();
    return compileShaderText(path, text.str());
}

std::shared_ptr<const ShaderKernel> buildKernel(const ShaderAst& ast,
                                                const ShaderBinding& binding) {
    return std::make_shared<const ShaderKernel>(lowerShader(ast, binding));
}

}  // namespace mpshade
