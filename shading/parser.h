// parser.h -- recursive-descent parser for one `surface NAME(params) { body }`.
#pragma once

#include <string>

#include "shading/ast.h"

namespace mpshade {

// Parses shader source text; `file` names it in diagnostics. Throws InputError with
// file:line:col and what was expected.
ShaderAst parseShader(const std::string& file, const std::string& text);

}  // namespace mpshade
