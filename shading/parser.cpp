#include "shading/parser.h"

#include <algorithm>

#include "geometry/error.h"

namespace mpshade {
namespace {

bool typeFromName(const std::string& s, ValueType& t) {
    static const struct {
        const char* name;
        ValueType type;
    } kTypes[] = {{"float", ValueType::Float},   {"int", ValueType::Int},
                  {"color", ValueType::Color},   {"point", ValueType::Point},
                  {"vector", ValueType::Vector}, {"normal", ValueType::Normal}};
    for (const auto& k : kTypes) {
        if (s == k.name) {
            t = k.type;
            return true;
        }
    }
    return false;
}

class Parser {
  public:
    Parser(const std::string& file, std::vector<Token> tokens)
        : file_(file), tokens_(std::move(tokens)) {}

    ShaderAst shader() {
        ShaderAst ast;
        ast.file = file_;
        const Token& kw = peek();
        if (kw.kind != TokenKind::Identifier || kw.text != "surface")
            fail(kw, "expected 'surface' to begin the shader, found " + spell(kw));
        next();
        const Token& name = expect(TokenKind::Identifier, "the shader's name");
        ast.name = name.text;
        ast.line = name.line;
        ast.column = name.column;
        expect(TokenKind::LParen, "'(' after the shader's name");
        if (peek().kind != TokenKind::RParen) {
            for (;;) {
                ast.params.push_back(param());
                if (peek().kind != TokenKind::Comma) break;
                next();
            }
        }
        expect(TokenKind::RParen, "')' or ',' in the parameter list");
        ast.body = block();
        if (peek().kind != TokenKind::End)
            fail(peek(), "expected end of file after the shader body, found " + spell(peek()));
        return ast;
    }

  private:
    const Token& peek(int ahead = 0) const {
        size_t k = pos_ + static_cast<size_t>(ahead);
        return tokens_[k < tokens_.size() ? k : tokens_.size() - 1];
    }
    const Token& next() {
        const Token& t = tokens_[pos_];
        if (pos_ + 1 < tokens_.size()) ++pos_;
        return t;
    }
    static std::string spell(const Token& t) {
        if (t.kind == TokenKind::End) return "end of file";
        return "'" + t.text + "'";
    }
    [[noreturn]] void fail(const Token& at, const std::string& message) const {
        throw InputError({file_, at.line, at.column, {}}, message);
    }
    // One level of nesting for as long as it lives.
    class Nest {
      public:
        Nest(Parser& parser, const Token& at) : parser_(parser) {
            if (++parser_.nesting_ > kMaxShaderNesting) parser_.tooDeep(at);
        }
        ~Nest() { --parser_.nesting_; }
        Nest(const Nest&) = delete;
        Nest& operator=(const Nest&) = delete;

      private:
        Parser& parser_;
    };
    [[noreturn]] void tooDeep(const Token& at) const {
        fail(at, "the shader nests more than " + std::to_string(kMaxShaderNesting) +
                     " levels deep here (blocks, parentheses and operators each count one; "
                     "a chain like a + b + c one per operator): split it with variables");
    }
    // Sets e's height from its operands and checks the depth it reaches.
    std::unique_ptr<Expr> measured(std::unique_ptr<Expr> e, const Token& at) const {
        int below = 0;
        for (const auto& a : e->args) below = std::max(below, a->height);
        e->height = below + 1;
        if (nesting_ + e->height - 1 > kMaxShaderNesting) tooDeep(at);
        return e;
    }
    const Token& expect(TokenKind kind, const std::string& what) {
        if (peek().kind != kind) fail(peek(), "expected " + what + ", found " + spell(peek()));
        return next();
    }

    ParamDecl param() {
        const Token& typeTok = expect(TokenKind::Identifier, "a parameter type");
        ParamDecl p;
        if (!typeFromName(typeTok.text, p.type))
            fail(typeTok,
                 "expected a parameter type (float, int, color, point, vector, normal), found " +
                     spell(typeTok));
        const Token& name = expect(TokenKind::Identifier, "the parameter's name");
        p.name = name.text;
        p.line = name.line;
        p.column = name.column;
        expect(TokenKind::Assign, "'=' and a default value for parameter '" + p.name + "'");
        p.defaultValue = expression();
        return p;
    }

    std::unique_ptr<Stmt> makeStmt(Stmt::Kind kind, const Token& at) {
        auto s = std::make_unique<Stmt>();
        s->kind = kind;
        s->line = at.line;
        s->column = at.column;
        return s;
    }

    std::unique_ptr<Stmt> block() {
        const Token& open = expect(TokenKind::LBrace, "'{'");
        auto b = makeStmt(Stmt::Kind::Block, open);
        while (peek().kind != TokenKind::RBrace) {
            if (peek().kind == TokenKind::End)
                fail(peek(), "expected '}' to close the block opened at line " +
                                 std::to_string(open.line) + ", found end of file");
            b->body.push_back(statement());
        }
        next();
        return b;
    }

    // A statement without its trailing ';' (also used in for-headers).
    std::unique_ptr<Stmt> simpleStatement() {
        const Token& first = peek();
        ValueType t;
        if (first.kind == TokenKind::Identifier && typeFromName(first.text, t) &&
            peek(1).kind == TokenKind::Identifier) {
            next();
            auto s = makeStmt(Stmt::Kind::Decl, first);
            s->declType = t;
            const Token& name = next();
            s->name = name.text;
            s->line = name.line;
            s->column = name.column;
            expect(TokenKind::Assign, "'=' and an initializer for '" + s->name + "'");
            s->value = expression();
            return s;
        }
        auto e = expression();
        const TokenKind k = peek().kind;
        if (k == TokenKind::Assign || k == TokenKind::PlusAssign || k == TokenKind::MinusAssign ||
            k == TokenKind::StarAssign || k == TokenKind::SlashAssign) {
            const Token& opTok = next();
            if (e->kind != Expr::Kind::Name &&
                !(e->kind == Expr::Kind::Index && e->args[0]->kind == Expr::Kind::Name))
                fail(opTok, "the left side of " + spell(opTok) +
                                " must be a variable or a component of one");
            auto s = makeStmt(Stmt::Kind::Assign, first);
            s->assignOp = k;
            s->target = std::move(e);
            s->value = expression();
            return s;
        }
        auto s = makeStmt(Stmt::Kind::ExprStmt, first);
        s->value = std::move(e);
        return s;
    }

    std::unique_ptr<Stmt> statement() {
        const Token& first = peek();
        const Nest nest(*this, first);
        if (first.kind == TokenKind::LBrace) return block();
        if (first.kind == TokenKind::Identifier && first.text == "if") {
            next();
            auto s = makeStmt(Stmt::Kind::If, first);
            expect(TokenKind::LParen, "'(' after 'if'");
            s->value = expression();
            expect(TokenKind::RParen, "')' after the condition");
            s->body.push_back(statement());
            if (peek().kind == TokenKind::Identifier && peek().text == "else") {
                next();
                s->elseBody.push_back(statement());
            }
            return s;
        }
        if (first.kind == TokenKind::Identifier && first.text == "for") {
            next();
            auto s = makeStmt(Stmt::Kind::For, first);
            expect(TokenKind::LParen, "'(' after 'for'");
            s->init = simpleStatement();
            expect(TokenKind::Semicolon, "';' after the loop's initializer");
            s->value = expression();
            expect(TokenKind::Semicolon, "';' after the loop's condition");
            s->step = simpleStatement();
            expect(TokenKind::RParen, "')' after the loop's step");
            s->body.push_back(statement());
            return s;
        }
        if (first.kind == TokenKind::Identifier &&
            (first.text == "while" || first.text == "do" || first.text == "return" ||
             first.text == "break" || first.text == "continue"))
            fail(first, "'" + first.text +
                            "' is not part of the shading language (v1 has if, for and blocks)");
        auto s = simpleStatement();
        expect(TokenKind::Semicolon, "';' after the statement");
        return s;
    }

    std::unique_ptr<Expr> makeExpr(Expr::Kind kind, const Token& at) {
        auto e = std::make_unique<Expr>();
        e->kind = kind;
        e->line = at.line;
        e->column = at.column;
        return e;
    }

    std::unique_ptr<Expr> expression() { return binary(0); }

    static int precedence(TokenKind k) {
        switch (k) {
            case TokenKind::OrOr:
                return 1;
            case TokenKind::AndAnd:
                return 2;
            case TokenKind::EqEq:
            case TokenKind::NotEq:
                return 3;
            case TokenKind::Less:
            case TokenKind::LessEq:
            case TokenKind::Greater:
            case TokenKind::GreaterEq:
                return 4;
            case TokenKind::Plus:
            case TokenKind::Minus:
                return 5;
            case TokenKind::Star:
            case TokenKind::Slash:
                return 6;
            default:
                return -1;
        }
    }

    // Precedence climbing; all binary operators are left associative.
    std::unique_ptr<Expr> binary(int minPrec) {
        auto lhs = unary();
        for (;;) {
            const Token& opTok = peek();
            const int prec = precedence(opTok.kind);
            if (prec < 0 || prec < minPrec) break;
            next();
            auto e = makeExpr(Expr::Kind::Binary, opTok);
            e->op = opTok.kind;
            e->args.push_back(std::move(lhs));
            e->args.push_back(binary(prec + 1));
            lhs = measured(std::move(e), opTok);
        }
        return lhs;
    }

    std::unique_ptr<Expr> unary() {
        const Token& t = peek();
        const Nest nest(*this, t);
        if (t.kind == TokenKind::Minus || t.kind == TokenKind::Bang || t.kind == TokenKind::Plus) {
            next();
            auto operand = unary();
            if (t.kind == TokenKind::Plus) return operand;
            auto e = makeExpr(Expr::Kind::Unary, t);
            e->op = t.kind;
            e->args.push_back(std::move(operand));
            return measured(std::move(e), t);
        }
        return postfix();
    }

    std::unique_ptr<Expr> postfix() {
        auto e = primary();
        while (peek().kind == TokenKind::LBracket) {
            const Token& open = next();
            auto idx = makeExpr(Expr::Kind::Index, open);
            idx->args.push_back(std::move(e));
            idx->args.push_back(expression());
            expect(TokenKind::RBracket, "']' after the component index");
            e = measured(std::move(idx), open);
        }
        return e;
    }

    std::unique_ptr<Expr> primary() {
        const Token& t = peek();
        switch (t.kind) {
            case TokenKind::IntLiteral:
            case TokenKind::FloatLiteral: {
                next();
                auto e = makeExpr(Expr::Kind::Number, t);
                e->number = t.number;
                e->isInt = t.kind == TokenKind::IntLiteral;
                return e;
            }
            case TokenKind::LParen: {
                next();
                auto e = expression();
                expect(TokenKind::RParen, "')'");
                return e;
            }
            case TokenKind::Identifier: {
                next();
                if (peek().kind == TokenKind::LParen) {
                    next();
                    auto call = makeExpr(Expr::Kind::Call, t);
                    call->name = t.text;
                    if (peek().kind != TokenKind::RParen) {
                        for (;;) {
                            call->args.push_back(expression());
                            if (peek().kind != TokenKind::Comma) break;
                            next();
                        }
                    }
                    expect(TokenKind::RParen, "')' or ',' in the call to '" + t.text + "'");
                    return measured(std::move(call), t);
                }
                auto e = makeExpr(Expr::Kind::Name, t);
                e->name = t.text;
                return e;
            }
            default:
                fail(t, "expected an expression, found " + spell(t));
        }
    }

    std::string file_;
    std::vector<Token> tokens_;
    size_t pos_ = 0;
    int nesting_ = 0;  // statements and operands being parsed, innermost included
};

}  // namespace

ShaderAst parseShader(const std::string& file, const std::string& text) {
    Parser parser(file, tokenize(file, text));
    return parser.shader();
}

}  // namespace mpshade
