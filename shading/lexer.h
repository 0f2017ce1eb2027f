// lexer.h -- tokens of the shading language (see the spec's shading-language.md).
#pragma once

#include <string>
#include <vector>

namespace mpshade {

enum class TokenKind {
    Identifier,
    IntLiteral,
    FloatLiteral,
    LParen,
    RParen,
    LBrace,
    RBrace,
    LBracket,
    RBracket,
    Comma,
    Semicolon,
    Plus,
    Minus,
    Star,
    Slash,
    Bang,
    Less,
    LessEq,
    Greater,
    GreaterEq,
    EqEq,
    NotEq,
    AndAnd,
    OrOr,
    Assign,
    PlusAssign,
    MinusAssign,
    StarAssign,
    SlashAssign,
    End,
};

struct Token {
    TokenKind kind;
    std::string text;  // the source spelling
    int line = 1;      // 1-based
    int column = 1;    // 1-based
    double number = 0.0;
};

// How a token kind reads in a diagnostic: "';'", "identifier", "end of file".
std::string describe(TokenKind kind);

// Splits `text` into tokens ending with End. Throws InputError naming file:line:col for a
// stray character, an unterminated comment or a malformed number.
std::vector<Token> tokenize(const std::string& file, const std::string& text);

}  // namespace mpshade
