// parser.h -- recursive-descent parser for one `surface NAME(params) { body }`.
#pragma once

#include <string>

#include "shading/ast.h"

namespace mpshade {

// How deep a shader may nest: statements (blocks, if, for) and expressions (parentheses,
// unary and binary operators, calls, indices) each count a level, and a chain of binary
// operators one level per operator (`a + b + c` is two deep). Every later stage walks the
// tree recursively, so the parser stops a deeper shader with a located error rather than
// let a generated or hostile file overflow the stack.
inline constexpr int kMaxShaderNesting = 512;

// Parses shader source text; `file` names it in diagnostics. Throws InputError with
// file:line:col and what was expected.
ShaderAst parseShader(const std::string& file, const std::string& text);

}  // namespace mpshade
