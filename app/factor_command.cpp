#include "app/factor_command.h"

#include <cstdio>
#include <filesystem>
#include <sstream>

#include <nlohmann/json.hpp>

#include "geometry/error.h"
#include "scene/scene.h"
#include "scene/variability.h"
#include "shading/factoring.h"
#include "shading/shader_compiler.h"

namespace mpshade {
namespace {

std::string sourceLine(const std::string& source, int line) {
    std::istringstream in(source);
    std::string text;
    for (int i = 1; std::getline(in, text); ++i)
        if (i == line) {
            const size_t first = text.find_first_not_of(" \t");
            return first == std::string::npos ? std::string() : text.substr(first);
        }
    return {};
}

// Channels k .. k + 2 that are the three components of one value form one row.
int groupSize(const std::vector<ChannelInfo>& c, size_t k) {
    if (k + 2 < c.size() && isTriple(c[k].type) && c[k].component == 0 && c[k + 1].component == 1 &&
        c[k + 2].component == 2 && c[k + 1].line == c[k].line && c[k + 2].line == c[k].line &&
        c[k + 1].column == c[k].column && c[k + 2].column == c[k].column)
        return 3;
    return 1;
}

std::string channelLabel(const ChannelInfo& c, int group) {
    std::string name = c.name;
    if (group == 3 && !name.empty() && name.back() == ']') name = name.substr(0, name.rfind('['));
    if (!name.empty()) return name;
    return std::string("(") + opName(c.op) + ")";
}

ShaderBinding defaultBinding() {
    // Without a scene: parameters at their defaults and a fixed ambient and distant light.
    ShaderBinding b;
    b.lights.resize(2);
    b.lights[0].kind = LightKind::Ambient;
    for (float& c : b.lights[0].color) c = 0.1f;
    b.lights[1].kind = LightKind::Distant;
    return b;
}

// The binding to factor for: --scene's --object (its parameters checked against the
// shader's), or parameters at their defaults with a fixed ambient and distant light;
// `described` says which.
ShaderBinding bindingFor(const FactorCommandOptions& options, const ShaderAst& ast,
                         std::string& described) {
    ShaderBinding binding = defaultBinding();
    described = "parameters at their defaults, a fixed ambient and a fixed distant light";
    if (!options.scene.empty() || !options.object.empty()) {
        if (options.scene.empty())
            throw InputError({"--object", 0, 0, {}}, "--object needs --scene");
        if (options.object.empty())
            throw InputError({"--scene", 0, 0, {}}, "--scene needs --object NAME");
        const Scene scene = loadScene(options.scene);
        const SceneObject* object = nullptr;
        std::string names;
        for (const SceneObject& o : scene.objects) {
            if (o.name == options.object) object = &o;
            names += (names.empty() ? "" : ", ") + o.name;
        }
        if (!object)
            throw InputError({"--object", 0, 0, {}}, "no object named '" + options.object +
                                                         "' in " + options.scene +
                                                         " (objects: " + names + ")");
        for (const ParamValue& p : object->params) {
            bool declared = false;
            for (const ParamDecl& d : ast.params) declared = declared || d.name == p.name;
            if (!declared)
                throw InputError({options.shader, 0, 0, {}},
                                 "object '" + object->name + "' binds parameter '" + p.name +
                                     "', which this shader does not declare");
        }
        binding = bindingOf(scene, *object);
        described = "object '" + object->name + "' in " + options.scene;
    }
    return binding;
}

// --json: the factoring as one document.
void printFactoringJson(const FactorCommandOptions& options, const ShaderAst& ast,
                        const std::string& bindingText, const FactoredShader& f, double ratio) {
    nlohmann::json channels = nlohmann::json::array();
    for (size_t k = 0; k < f.channels.size(); ++k) {
        const ChannelInfo& c = f.channels[k];
        channels.push_back({{"index", k},
                            {"name", c.name},
                            {"type", typeName(c.type)},
                            {"component", c.component},
                            {"line", c.line},
                            {"column", c.column},
                            {"op", opName(c.op)},
                            {"source", sourceLine(ast.source, c.line)}});
    }
    auto linesJson = [&](const std::vector<DynamicLine>& from) {
        nlohmann::json lines = nlohmann::json::array();
        for (const DynamicLine& l : from)
            lines.push_back(
                {{"line", l.line}, {"source", sourceLine(ast.source, l.line)}, {"chain", l.chain}});
        return lines;
    };
    nlohmann::json doc = {{"shader", ast.name},
                          {"file", options.shader},
                          {"binding", bindingText},
                          {"naive_width", f.naiveWidth},
                          {"chosen_width", f.chosenWidth},
                          {"channels", channels},
                          {"instructions",
                           {{"unfactored", f.originalInstructions},
                            {"static", f.staticInstructions},
                            {"dynamic", f.dynamicInstructions}}},
                          {"cost",
                           {{"unfactored", f.originalCost},
                            {"static", f.staticCost},
                            {"dynamic", f.dynamicCost},
                            {"static_repeated", f.recomputedStaticCost}}},
                          {"dynamic_to_static_instructions", ratio},
                          {"dynamic_lines", linesJson(f.dynamicLines)},
                          {"baked_lines", linesJson(f.bakedLines)}};
    std::printf("%s\n", doc.dump(2).c_str());
}

// The factoring for a reader: the n-tuple's channels, the costs, the dynamic lines with
// what reaches them, and with --dump both parts.
void printFactoring(const FactorCommandOptions& options, const ShaderAst& ast,
                    const std::string& bindingText, const FactoredShader& f, double ratio,
                    int storeAboveCost) {
    std::printf("%s (%s), factored for %s\n\n", ast.name.c_str(), options.shader.c_str(),
                bindingText.c_str());
    std::printf("n-tuple: %d float%s (storing every static value a dynamic operation reads: %d)\n",
                f.chosenWidth, f.chosenWidth == 1 ? "" : "s", f.naiveWidth);
    if (f.recomputedStaticCost > 0)
        std::printf(
            "  %s: %d cost units of static work a point, cheaper to repeat than "
            "to read back (--store-above-cost %d), run by the dynamic part\n",
            f.chosenWidth == 0 ? "nothing stored" : "some not stored", f.recomputedStaticCost,
            storeAboveCost);
    if (!f.channels.empty())
        std::printf("  %-9s %-7s %-18s %s\n", "channel", "type", "holds", "computed at");
    for (size_t k = 0; k < f.channels.size();) {
        const int group = groupSize(f.channels, k);
        const ChannelInfo& c = f.channels[k];
        const std::string index =
            group == 3 ? std::to_string(k) + "-" + std::to_string(k + 2) : std::to_string(k);
        const char* type = group == 3 ? typeName(c.type) : "float";
        std::printf("  %-9s %-7s %-18s line %d:%d  %s\n", index.c_str(), type,
                    channelLabel(c, group).c_str(), c.line, c.column,
                    sourceLine(ast.source, c.line).c_str());
        k += static_cast<size_t>(group);
    }
    std::printf("\nper sample         instructions   cost units\n");
    std::printf("  unfactored       %12d %12d\n", f.originalInstructions, f.originalCost);
    std::printf("  static part      %12d %12d\n", f.staticInstructions, f.staticCost);
    std::printf("  dynamic part     %12d %12d\n", f.dynamicInstructions, f.dynamicCost);
    if (f.staticInstructions > 0)
        std::printf("  dynamic/static   %12.2f %12.2f\n", ratio,
                    f.staticCost > 0 ? double(f.dynamicCost) / f.staticCost : 0.0);
    auto printLines = [&](const std::vector<DynamicLine>& lines) {
        for (const DynamicLine& l : lines) {
            std::printf("  %3d | %s\n", l.line, sourceLine(ast.source, l.line).c_str());
            std::string chain;
            for (const std::string& step : l.chain)
                chain += (chain.empty() ? "" : "\n        <- ") + step;
            std::printf("        <- %s\n", chain.c_str());
        }
    };
    std::printf("\ndynamic lines (and the input that reaches them):\n");
    if (f.dynamicLines.empty())
        std::printf("  none: the whole shader is static for this binding\n");
    printLines(f.dynamicLines);
    if (!f.bakedLines.empty()) {
        std::printf(
            "\nbaked lines: stored, computed once by the static phase with the input that "
            "reaches them frozen at its representative value (the time, view, parameter or "
            "light of each static run; the object's range bounds the view's):\n");
        printLines(f.bakedLines);
    }
    if (options.dump) {
        std::printf("\nstatic part:\n%s\ndynamic part:\n%s", f.staticPart.dump().c_str(),
                    f.dynamicPart.dump().c_str());
    }
}

}  // namespace

int runFactorCommand(const FactorCommandOptions& options) {
    auto ast = loadShaderFile(options.shader);
    std::string bindingText;
    const ShaderBinding binding = bindingFor(options, *ast, bindingText);
    FactorOptions factorOptions;
    factorOptions.storeAboveCost = options.storeAboveCost;
    const FactoredShader f = factorShader(*ast, binding, factorOptions);
    const double ratio =
        f.staticInstructions > 0 ? double(f.dynamicInstructions) / f.staticInstructions : 0.0;
    if (options.json)
        printFactoringJson(options, *ast, bindingText, f, ratio);
    else
        printFactoring(options, *ast, bindingText, f, ratio, factorOptions.storeAboveCost);
    return 0;
}

}  // namespace mpshade
