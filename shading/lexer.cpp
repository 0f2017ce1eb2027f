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

namespace {

// The lexer's position in one file's text, with its line and column for errors.
class Lexer {
  public:
    Lexer(const std::string& file, const std::string& text) : file_(file), text_(text) {}

    std::vector<Token> run() {
        std::vector<Token> tokens;
        while (skipSpaceAndComments()) {
            Token tok{TokenKind::End, "", line_, col_, 0.0};
            const size_t start = i_;
            const char c = text_[i_];
            if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
                while (i_ < text_.size() &&
                       (std::isalnum(static_cast<unsigned char>(text_[i_])) || text_[i_] == '_'))
                    advance(1);
                tok.kind = TokenKind::Identifier;
            } else if (isDigit(i_) || (c == '.' && isDigit(i_ + 1))) {
                number(start, tok);
            } else {
                punctuation(tok);
            }
            tok.text = text_.substr(start, i_ - start);
            tokens.push_back(std::move(tok));
        }
        tokens.push_back({TokenKind::End, "", line_, col_, 0.0});
        return tokens;
    }

  private:
    bool isDigit(size_t at) const {
        return at < text_.size() && std::isdigit(static_cast<unsigned char>(text_[at]));
    }
    void advance(size_t n) {
        for (size_t k = 0; k < n && i_ < text_.size(); ++k, ++i_) {
            if (text_[i_] == '\n') {
                ++line_;
                col_ = 1;
            } else {
                ++col_;
            }
        }
    }
    [[noreturn]] void fail(int l, int c, const std::string& msg) const {
        throw InputError({file_, l, c, {}}, msg);
    }

    // Past white space and comments; false at the end of the text.
    bool skipSpaceAndComments() {
        while (i_ < text_.size()) {
            const char c = text_[i_];
            if (c == ' ' || c == '\t' || c == '\r' || c == '\n') {
                advance(1);
            } else if (c == '/' && i_ + 1 < text_.size() && text_[i_ + 1] == '/') {
                while (i_ < text_.size() && text_[i_] != '\n') advance(1);
            } else if (c == '/' && i_ + 1 < text_.size() && text_[i_ + 1] == '*') {
                const int l0 = line_, c0 = col_;
                advance(2);
                while (i_ < text_.size() &&
                       !(text_[i_] == '*' && i_ + 1 < text_.size() && text_[i_ + 1] == '/'))
                    advance(1);
                if (i_ >= text_.size()) fail(l0, c0, "unterminated /* comment");
                advance(2);
            } else {
                return true;
            }
        }
        return false;
    }

    // An int or float literal: digits, a fraction, an exponent; ints at most 2^24, floats
    // within float range.
    void number(size_t start, Token& tok) {
        bool isFloat = false;
        while (isDigit(i_)) advance(1);
        if (i_ < text_.size() && text_[i_] == '.') {
            isFloat = true;
            advance(1);
            while (isDigit(i_)) advance(1);
        }
        if (i_ < text_.size() && (text_[i_] == 'e' || text_[i_] == 'E')) {
            isFloat = true;
            advance(1);
            if (i_ < text_.size() && (text_[i_] == '+' || text_[i_] == '-')) advance(1);
            if (!isDigit(i_))
                fail(tok.line, tok.column, "malformed number: exponent has no digits");
            while (isDigit(i_)) advance(1);
        }
        if (i_ < text_.size() &&
            (std::isalpha(static_cast<unsigned char>(text_[i_])) || text_[i_] == '_'))
            fail(line_, col_, "malformed number: unexpected '" + std::string(1, text_[i_]) + "'");
        const std::string spelled = text_.substr(start, i_ - start);
        tok.number = std::strtod(spelled.c_str(), nullptr);
        if (!std::isfinite(tok.number) || std::fabs(tok.number) > 3.4e38)
            fail(tok.line, tok.column, "number '" + spelled + "' is out of range");
        if (!isFloat && tok.number > 16777216.0)
            fail(tok.line, tok.column, "integer '" + spelled + "' is out of range (at most 2^24)");
        tok.kind = isFloat ? TokenKind::FloatLiteral : TokenKind::IntLiteral;
    }

    // An operator or punctuation mark, two characters before one.
    void punctuation(Token& tok) {
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
        const char c = text_[i_];
        for (const Op& op : ops2)
            if (c == op.a && i_ + 1 < text_.size() && text_[i_ + 1] == op.b) {
                tok.kind = op.kind;
                advance(2);
                return;
            }
        for (const Op& op : ops1)
            if (c == op.a) {
                tok.kind = op.kind;
                advance(1);
                return;
            }
        if (c == '"' || c == '\'')
            fail(line_, col_,
                 "strings are not part of the shading language: shaders are procedural and "
                 "read no files (docs/shading-language.md)");
        const std::string shown = std::isprint(static_cast<unsigned char>(c))
                                      ? std::string(1, c)
                                      : "\\x" + std::to_string(static_cast<unsigned char>(c));
        fail(line_, col_, "unexpected character '" + shown + "'");
    }

    const std::string& file_;
    const std::string& text_;
    size_t i_ = 0;
    int line_ = 1, col_ = 1;
};

}  // namespace

std::vector<Token> tokenize(const std::string& file, const std::string& text) {
    return Lexer(file, text).run();
}

}  // namespace mpshade
