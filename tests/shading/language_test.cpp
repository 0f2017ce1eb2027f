// The language front end: every malformed shader gives file:line:col and what was expected
// (golden messages), and every example shader compiles.
#include <filesystem>

#include <gtest/gtest.h>

#include "geometry/error.h"
#include "scene/variability.h"
#include "shading/factoring.h"
#include "shading/lower.h"
#include "shading/parser.h"
#include "shading/shader_compiler.h"
#include "test_support.h"

namespace mpshade {
namespace {

struct BadShader {
    const char* source;
    int line, column;
    const char* message;
};

const BadShader kBadShaders[] = {
    {"", 1, 1, "expected 'surface' to begin the shader, found end of file"},
    {"shader s() { Ci = 1; }", 1, 1, "expected 'surface' to begin the shader, found 'shader'"},
    {"surface () {}", 1, 9, "expected the shader's name, found '('"},
    {"surface s(float a) { Ci = 1; }", 1, 18,
     "expected '=' and a default value for parameter 'a', found ')'"},
    {"surface s(string a = 1) { Ci = 1; }", 1, 11,
     "expected a parameter type (float, int, color, point, vector, normal), found 'string'"},
    {"surface s() {\n  float a = 1.0\n  Ci = color(a);\n}", 3, 3,
     "expected ';' after the statement, found 'Ci'"},
    {"surface s() {\n  Ci = color(1, 2;\n}", 2, 18,
     "expected ')' or ',' in the call to 'color', found ';'"},
    {"surface s() {\n  Ci = 1;\n", 3, 1,
     "expected '}' to close the block opened at line 1, found end of file"},
    {"surface s() { Ci = 1; } extra", 1, 25,
     "expected end of file after the shader body, found 'extra'"},
    {"surface s() { Ci = 1 @ 2; }", 1, 22, "unexpected character '@'"},
    {"surface s() { /* open", 1, 15, "unterminated /* comment"},
    {"surface s() { Ci = 1.5e; }", 1, 20, "malformed number: exponent has no digits"},
    {"surface s() { Ci = 12ab; }", 1, 22, "malformed number: unexpected 'a'"},
    {"surface s() { Ci = q; }", 1, 20, "unknown variable 'q'"},
    {"surface s() { Ci = nois(P); }", 1, 20, "unknown function 'nois'"},
    {"surface s() { Ci = noise; }", 1, 20, "'noise' is a function; call it with '(...)'"},
    {"surface s() { Ci = noise(P, P); }", 1, 20, "'noise' takes 1 argument, not 2"},
    {"surface s() { Ci = dot(1.0, P); }", 1, 20,
     "argument 1 of 'dot' must be a color, point, vector or normal, not float"},
    {"surface s() { float a = 1; Ci = color(a); int b = a; }", 1, 51,
     "cannot initialize int 'b' with a float (use int(x) to truncate)"},
    {"surface s() { color c = P; Ci = c; }", 1, 25,
     "cannot initialize color 'c' with a point (convert explicitly with color(x))"},
    {"surface s() { P = 1; Ci = 1; }", 1, 15, "'P' is a read-only global"},
    {"surface s() { float a = 1; float a = 2; Ci = 1; }", 1, 34,
     "'a' is already declared in this scope"},
    {"surface s() { float N = 1; Ci = 1; }", 1, 21, "'N' is a global and cannot be redeclared"},
    {"surface s() { Oi = 1; }", 1, 9, "shader 's' never assigns Ci"},
    {"surface s() { Ci = 1; if (P) { Ci = 0; } }", 1, 27,
     "the condition of 'if' must be a float or int, not point"},
    {"surface s() { Ci = 1; if (P < 1) { Ci = 0; } }", 1, 29,
     "cannot order point and int; compare components"},
    {"surface s() { Ci = color(u)[3]; }", 1, 29,
     "a component index must be a whole number in [0, 2]"},
    {"surface s() { float i = 1; Ci = color(u)[i]; }", 1, 42, "a component index must be an int"},
    {"surface s() { Ci = fbm(P, 20); }", 1, 27,
     "the octave count must be a whole number in [1, 16]"},
    {"surface s() { Ci = occlusion(P, N, int(u)); }", 1, 36,
     "the occlusion ray count must be a constant"},
    {"surface s() { float a = 0; for (int i = 0; i < u; i += 1) { a += 1; } Ci = a; }", 1, 46,
     "the loop condition must be constant after folding (loops are unrolled); it depends on u"},
    {"surface s() { float a = 0; for (int i = 0; i < time * P[1] + v; i += 1) { a += 1; } "
     "Ci = a; }",
     1, 46,
     "the loop condition must be constant after folding (loops are unrolled); it depends on "
     "time, P and v"},
    {"surface s() { Ci = color(1); noise(P); }", 1, 30,
     "this statement does nothing: an expression alone has no effect (the language has no side "
     "effects); assign its value, as in 'float y = ...;'"},
    {"surface s() { float x = u; bake(x); Ci = x; }", 1, 28,
     "this statement does nothing: an expression alone has no effect (the language has no side "
     "effects); assign its value, as in 'float y = ...;'"},
    {"surface s() { Ci = bake(1 + dynamic(noise(P))); }", 1, 29,
     "dynamic() inside bake() (line 1:20): bake() computes its whole argument in the static "
     "phase, so this dynamic() would have no effect; remove one of them"},
    {"surface s() { Ci = texture(\"bricks.tx\", s, t); }", 1, 28,
     "strings are not part of the shading language: shaders are procedural and read no files "
     "(docs/shading-language.md)"},
    {"surface s() { Ci = texture(s, t); }", 1, 20,
     "unknown function 'texture': shaders are procedural and read no image files (use noise, "
     "fbm, turbulence or cellnoise)"},
    {"surface s() { float a = 0; for (int i = 0; i < 10; i += 0) { a += 1; } Ci = a; }", 1, 28,
     "the loop runs more than 4096 iterations"},
    {"surface s() { while (1) {} Ci = 1; }", 1, 15,
     "'while' is not part of the shading language (v1 has if, for and blocks)"},
    {"surface s(float a = u) { Ci = a; }", 1, 21, "the default of 'a' must be a constant"},
    {"surface s(float a = 1, float a = 2) { Ci = a; }", 1, 30, "parameter 'a' is declared twice"},
    {"surface s(float P = 1) { Ci = 1; }", 1, 17, "parameter 'P' has the name of a global"},
    {"surface s() { Ci = 1 + ; }", 1, 24, "expected an expression, found ';'"},
    {"surface s() { Ci = 16777217; }", 1, 20, "integer '16777217' is out of range (at most 2^24)"},
    {"surface s() { 1 = 2; Ci = 1; }", 1, 17,
     "the left side of '=' must be a variable or a component of one"},
};

TEST(LanguageErrors, GoldenMessages) {
    for (const BadShader& bad : kBadShaders) {
        try {
            auto ast = compileShaderText("bad.sl", bad.source);
            lowerShader(*ast, {});
            ADD_FAILURE() << "accepted: " << bad.source;
        } catch (const InputError& e) {
            EXPECT_EQ(e.message(), bad.message) << bad.source;
            EXPECT_EQ(e.where().line, bad.line) << bad.source;
            EXPECT_EQ(e.where().column, bad.column) << bad.source;
            EXPECT_EQ(e.where().file, "bad.sl");
            EXPECT_EQ(std::string(e.what()).rfind("bad.sl:" + std::to_string(bad.line) + ":", 0),
                      0u)
                << e.what();
        }
    }
}

TEST(LanguageErrors, AnAnimatedLoopBoundNamesItsParameter) {
    // Constant at its default the loop unrolls; animated by the scene it cannot, and the
    // message says which input is to blame.
    auto ast = compileShaderText(
        "k.sl",
        "surface s(float k = 2) { float a = 0; for (int i = 0; i < k; i += 1) { a += 1; } "
        "Ci = a; }");
    EXPECT_NO_THROW(lowerShader(*ast, {}));
    ShaderBinding b;
    b.params["k"].kind = ParamBinding::Kind::Animated;
    try {
        lowerShader(*ast, b);
        ADD_FAILURE() << "an animated loop bound was accepted";
    } catch (const InputError& e) {
        EXPECT_EQ(e.message(),
                  "the loop condition must be constant after folding (loops are unrolled); it "
                  "depends on parameter 'k' (animated in this scene)");
    }
}

// The column of the first error of `source`, or 0 if it compiles and factors.
int errorColumn(const std::string& source, std::string* message = nullptr) {
    try {
        auto ast = compileShaderText("deep.sl", source);
        lowerShader(*ast, {});
        factorShader(*ast, {});
        return 0;
    } catch (const InputError& e) {
        if (message) *message = e.message();
        return e.where().column;
    }
}

std::string repeat(const std::string& s, int n) {
    std::string out;
    for (int i = 0; i < n; ++i) out += s;
    return out;
}

TEST(LanguageErrors, NestingIsBoundedOnTheBoundary) {
    // `float x = (...(1)...)` with k parentheses: the statement is one level, each operand
    // one more, so k = kMaxShaderNesting - 2 is the deepest accepted; it must also get
    // through type checking, lowering and factoring (recursive) without overflowing the
    // stack, which the sanitizer build checks with its larger frames.
    const auto parens = [](int k) {
        return "surface s() { float x = " + repeat("(", k) + "u" + repeat(")", k) +
               "; Ci = color(x); }";
    };
    EXPECT_EQ(errorColumn(parens(kMaxShaderNesting - 2)), 0);
    std::string message;
    const int prefix = static_cast<int>(std::string("surface s() { float x = ").size());
    EXPECT_EQ(errorColumn(parens(kMaxShaderNesting - 1), &message),
              prefix + kMaxShaderNesting - 1 + 1)
        << "points at the operand one level too deep";
    EXPECT_NE(message.find("nests more than 512 levels"), std::string::npos) << message;
    // A chain of n terms is n - 1 levels deep under its statement.
    const auto chain = [](int n) {
        return "surface s() { float x = u" + repeat(" + u", n - 1) + "; Ci = color(x); }";
    };
    EXPECT_EQ(errorColumn(chain(kMaxShaderNesting)), 0);
    EXPECT_GT(errorColumn(chain(kMaxShaderNesting + 1)), 0);
    // Nested blocks: the body's block is not a statement; each inner one is, then the
    // assignment, its call and the call's argument.
    const auto blocks = [](int k) {
        return "surface s() { " + repeat("{", k) + "Ci = color(u);" + repeat("}", k) + " }";
    };
    EXPECT_EQ(errorColumn(blocks(kMaxShaderNesting - 3)), 0);
    EXPECT_GT(errorColumn(blocks(kMaxShaderNesting - 2)), 0);
}

TEST(LanguageErrors, HostileNestingIsAnErrorNotACrash) {
    // Found crashing (stack overflow) before the parser bounded nesting.
    EXPECT_GT(errorColumn("surface s() { Ci = color(" + repeat("(", 100000) + "1" +
                          repeat(")", 100000) + "); }"),
              0);
    EXPECT_GT(errorColumn("surface s() { Ci = color(1" + repeat(" + 1", 199999) + "); }"), 0);
    EXPECT_GT(errorColumn("surface s() { Ci = color(" + repeat("-", 100000) + "1); }"), 0);
    EXPECT_GT(errorColumn("surface s() { Ci = color(u" + repeat("[0]", 100000) + "); }"), 0);
    EXPECT_GT(errorColumn("surface s() { " + repeat("if (u > 0) ", 100000) + "Ci = 1; }"), 0);
}

TEST(LanguageErrors, MissingFile) {
    try {
        loadShaderFile("/nonexistent/x.sl");
        FAIL();
    } catch (const InputError& e) {
        EXPECT_EQ(e.message(), "cannot open shader file");
    }
}

TEST(Language, EveryExampleShaderCompiles) {
    int count = 0;
    for (const auto& entry :
         std::filesystem::directory_iterator(test::sourcePath("examples/shaders"))) {
        if (entry.path().extension() != ".sl") continue;
        auto ast = loadShaderFile(entry.path().string());
        // With an ambient and a distant light, so lighting does not fold away.
        ShaderBinding binding;
        binding.lights.resize(2);
        binding.lights[0].kind = LightKind::Ambient;
        binding.lights[1].kind = LightKind::Distant;
        const IrProgram ir = lowerShader(*ast, binding);
        EXPECT_GT(ir.insts.size(), 5u) << entry.path();
        ++count;
    }
    EXPECT_GE(count, 5);
}

TEST(Language, CommentsAndPrecedence) {
    auto ast = compileShaderText("ok.sl",
                                 "// line\nsurface s() { /* block\n */ Ci = 1 + 2 * 3 - 4 / 2; }");
    const IrProgram ir = lowerShader(*ast, {});
    // 1 + 2 * 3 - 4 / 2 = 1 + 6 - 2 = 5 (integer division), folded to one constant.
    ASSERT_EQ(ir.insts.size(), 2u) << ir.dump();  // the constant 5 and Oi's constant 1
    for (const Inst& inst : ir.insts) {
        ASSERT_EQ(inst.op, Op::Const);
        if (inst.result == ir.ci[0]) {
            EXPECT_EQ(inst.constant, 5.0f);
        }
    }
}

}  // namespace
}  // namespace mpshade
