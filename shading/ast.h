// ast.h -- the shading language's syntax tree. Every node keeps its source position so any
// later stage (type checking, lowering, factoring reports) can point at the user's text.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "shading/lexer.h"
#include "shading/types.h"

namespace mpshade {

struct Expr {
    enum class Kind { Number, Name, Unary, Binary, Call, Index };
    Kind kind;
    int line = 0, column = 0;
    double number = 0.0;                      // Number
    bool isInt = false;                       // Number: an integer literal
    std::string name;                         // Name, Call
    TokenKind op = TokenKind::End;            // Unary, Binary
    std::vector<std::unique_ptr<Expr>> args;  // operands; Index: [base, index]
    ValueType type = ValueType::Void;         // filled in by the type checker
    int height = 1;                           // levels of the tree below and including it
};

struct Stmt {
    enum class Kind { Decl, Assign, ExprStmt, If, For, Block };
    Kind kind;
    int line = 0, column = 0;
    ValueType declType = ValueType::Void;    // Decl
    std::string name;                        // Decl
    TokenKind assignOp = TokenKind::Assign;  // Assign: = += -= *= /=
    std::unique_ptr<Expr> target;            // Assign: a Name or an Index of a Name
    std::unique_ptr<Expr> value;       // Decl initializer, Assign value, ExprStmt, If/For condition
    std::unique_ptr<Stmt> init, step;  // For
    std::vector<std::unique_ptr<Stmt>> body;      // Block; If then-part; For body
    std::vector<std::unique_ptr<Stmt>> elseBody;  // If
};

struct ParamDecl {
    ValueType type;
    std::string name;
    std::unique_ptr<Expr> defaultValue;
    int line = 0, column = 0;
};

struct ShaderAst {
    std::string file;    // as given by the user, for diagnostics
    std::string source;  // the text, for reports that quote it
    std::string name;
    int line = 0, column = 0;
    std::vector<ParamDecl> params;
    std::unique_ptr<Stmt> body;  // a Block
    bool oiIsColor = false;      // filled in by the type checker
};

}  // namespace mpshade
