#include "shading/lexer.h"

#include <cctype>
#include <cmath>
#include <cstdlib>

#include "geometry/error.h"

namespace mpshade {

std::string describe(TokenKind kind) {
    switch (kind) {
        case TokenKind::Identifier:
            return "identifier";
        case TokenKind::IntLiteral:
            return "integer";
        case TokenKind::FloatLiteral:
            return "number";
        case TokenKind::LParen:
            return "'('";
        case TokenKind::RParen:
            return "')'";
        case TokenKind::LBrace:
            return "'{'";
        case TokenKind::RBrace:
            return "'}'";
        case TokenKind::LBracket:
            return "'['";
        case TokenKind::RBracket:
            return "']'";
        case TokenKind::Comma:
            return "','";
        case TokenKind::Semicolon:
            return "';'";
        case TokenKind::Plus:
            return "'+'";
        case TokenKind::Minus:
            return "'-'";
        case TokenKind::Star:
            return "'*'";
        case TokenKind::Slash:
            return "'/'";
        case TokenKind::Bang:
            return "'!'";
        case TokenKind::Less:
            return "'<'";
        case TokenKind::LessEq:
            return "'<='";
        case TokenKind::Greater:
            return "'>'";
        case TokenKind::GreaterEq:
            return "'>='";
        case TokenKind::EqEq:
            return "'=='";
        case TokenKind::NotEq:
            return "'!='";
        case TokenKind::AndAnd:
            return "'&&'";
        case TokenKind::OrOr:
            return "'||'";
        case TokenKind::Assign:
            return "'='";
        case TokenKind::PlusAssign:
            return "'+='";
        case TokenKind::MinusAssign:
            return "'-='";
        case TokenKind::StarAssign:
            return "'*='";
        case TokenKind::SlashAssign:
            return "'/='";
        case TokenKind::End:
            return "end of file";
    }
    return "token";
}

std::vector<Token> tokenize(const std::string& file, const std::string& text) {
    std::vector<Token> tokens;
    size_t i = 0;
    int line = 1, col = 1;
    auto advance = [&](size_t n) {
        for (size_t k = 0; k < n && i < text.size(); ++k, ++i) {
            if (text[i] == '\n') {
                ++line;
                col = 1;
            } else {
                ++col;
            }
        }
    };
    auto fail = [&](int l, int c, const std::string& msg) -> void {
        throw InputError({file, l, c, {}}, msg);
    };
    while (i < text.size()) {
        const char c = text[i];
        if (c == ' ' || c == '\t' || c == '\r' || c == '\n') {
            advance(1);
            continue;
        }
        if (c == '/' && i + 1 < text.size() && text[i + 1] == '/') {
            while (i < text.size() && text[i] != '\n') advance(1);
            continue;
        }
        if (c == '/' && i + 1 < text.size() && text[i + 1] == '*') {
            const int l0 = line, c0 = col;
            advance(2);
            while (i < text.size() &&
                   !(text[i] == '*' && i + 1 < text.size() && text[i + 1] == '/'))
                advance(1);
            if (i >= text.size()) fail(l0, c0, "unterminated /* comment");
            advance(2);
            continue;
        }
        Token tok{TokenKind::End, "", line, col, 0.0};
        const size_t start = i;
        if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
            while (i < text.size() &&
                   (std::isalnum(static_cast<unsigned char>(text[i])) || text[i] == '_'))
                advance(1);
            tok.kind = TokenKind::Identifier;
        } else if (std::isdigit(static_cast<unsigned char>(c)) ||
                   (c == '.' && i + 1 < text.size() &&
                    std::isdigit(static_cast<unsigned char>(text[i + 1])))) {
            bool isFloat = false;
            while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) advance(1);
            if (i < text.size() && text[i] == '.') {
                isFloat = true;
                advance(1);
                while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i])))
                    advance(1);
            }
            if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
                isFloat = true;
                advance(1);
                if (i < text.size() && (text[i] == '+' || text[i] == '-')) advance(1);
                if (i >= text.size() || !std::isdigit(static_cast<unsigned char>(text[i])))
                    fail(tok.line, tok.column, "malformed number: exponent has no digits");
                while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i])))
                    advance(1);
            }
            if (i < text.size() &&
                (std::isalpha(static_cast<unsigned char>(text[i])) || text[i] == '_'))
                fail(line, col, "malformed number: unexpected '" + std::string(1, text[i]) + "'");
            const std::string spelled = text.substr(start, i - start);
            tok.number = std::strtod(spelled.c_str(), nullptr);
            if (!std::isfinite(tok.number) || std::fabs(tok.number) > 3.4e38)
                fail(tok.line, tok.column, "number '" + spelled + "' is out of range");
            if (!isFloat && tok.number > 16777216.0)
                fail(tok.line, tok.column,
                     "integer '" + spelled + "' is out of range (at most 2^24)");
            tok.kind = isFloat ? TokenKind::FloatLiteral : TokenKind::IntLiteral;
        } else {
            auto two = [&](char a, char b) {
                return c == a && i + 1 < text.size() && text[i + 1] == b;
            };
            struct Op {
                char a, b;
                TokenKind kind;
            };
            static const Op ops2[] = {
                {'<', '=', TokenKind::LessEq},     {'>', '=', TokenKind::GreaterEq},
                {'=', '=', TokenKind::EqEq},       {'!', '=', TokenKind::NotEq},
                {'&', '&', TokenKind::AndAnd},     {'|', '|', TokenKind::OrOr},
                {'+', '=', TokenKind::PlusAssign}, {'-', '=', TokenKind::MinusAssign},
                {'*', '=', TokenKind::StarAssign}, {'/', '=', TokenKind::SlashAssign}};
            static const Op ops1[] = {{'(', 0, TokenKind::LParen},   {')', 0, TokenKind::RParen},
                                      {'{', 0, TokenKind::LBrace},   {'}', 0, TokenKind::RBrace},
                                      {'[', 0, TokenKind::LBracket}, {']', 0, TokenKind::RBracket},
                                      {',', 0, TokenKind::Comma},    {';', 0, TokenKind::Semicolon},
                                      {'+', 0, TokenKind::Plus},     {'-', 0, TokenKind::Minus},
                                      {'*', 0, TokenKind::Star},     {'/', 0, TokenKind::Slash},
                                      {'!', 0, TokenKind::Bang},     {'<', 0, TokenKind::Less},
                                      {'>', 0, TokenKind::Greater},  {'=', 0, TokenKind::Assign}};
            bool found = false;
            for (const Op& op : ops2) {
                if (two(op.a, op.b)) {
                    tok.kind = op.kind;
                    advance(2);
                    found = true;
                    break;
                }
            }
            if (!found) {
                for (const Op& op : ops1) {
                    if (c == op.a) {
                        tok.kind = op.kind;
                        advance(1);
                        found = true;
                        break;
                    }
                }
            }
            if (!found) {
                std::string shown = std::isprint(static_cast<unsigned char>(c))
                                        ? std::string(1, c)
                                        : "\\x" + std::to_string(static_cast<unsigned char>(c));
                fail(line, col, "unexpected character '" + shown + "'");
            }
        }
        tok.text = text.substr(start, i - start);
        tokens.push_back(std::move(tok));
    }
    tokens.push_back({TokenKind::End, "", line, col, 0.0});
    return tokens;
}

}  // namespace mpshade
