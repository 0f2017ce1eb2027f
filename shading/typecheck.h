// typecheck.h -- resolves names and types over a parsed shader, and rejects ill-typed
// programs before anything is lowered (so a shader is never half-compiled).
#pragma once

#include "shading/ast.h"
#include "shading/builtins.h"

namespace mpshade {

// Fills in Expr::type everywhere; throws InputError naming file:line:col on the first error.
void typecheckShader(ShaderAst& ast);

// The type of `b` applied to arguments of the given types, or Void (with a reason in
// `why`) when they do not fit.
ValueType builtinResultType(Builtin b, const std::vector<ValueType>& args, std::string& why);

}  // namespace mpshade
