// shader_compiler.h -- from a .sl file to a runnable, binding-specialized kernel.
#pragma once

#include <memory>
#include <string>

#include "shading/ast.h"
#include "shading/binding.h"
#include "shading/interpreter.h"
#include "shading/ir.h"

namespace mpshade {

// Reads, parses and type checks a shader file. Throws InputError (file:line:col).
std::shared_ptr<const ShaderAst> loadShaderFile(const std::string& path);
// The same for text in memory; `file` names it in diagnostics.
std::shared_ptr<const ShaderAst> compileShaderText(const std::string& file,
                                                   const std::string& text);

// Lowers `ast` for one binding and prepares it for the interpreter.
std::shared_ptr<const ShaderKernel> buildKernel(const ShaderAst& ast, const ShaderBinding& binding);

}  // namespace mpshade
