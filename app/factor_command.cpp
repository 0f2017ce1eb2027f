#include "app/factor_command.h"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "geometry/error.h"
#include "phases/split_verification.h"
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

// An object's binding, its parameters checked against the shader's declarations.
ShaderBinding objectBinding(const Scene& scene, const SceneObject& object, const ShaderAst& ast,
                            const std::string& shaderFile) {
    for (const ParamValue& p : object.params) {
        bool declared = false;
        for (const ParamDecl& d : ast.params) declared = declared || d.name == p.name;
        if (!declared)
            throw InputError({shaderFile, 0, 0, {}}, "object '" + object.name +
                                                         "' binds parameter '" + p.name +
                                                         "', which this shader does not declare");
    }
    return bindingOf(scene, object);
}

const SceneObject& findObject(const Scene& scene, const FactorCommandOptions& options) {
    std::string names;
    for (const SceneObject& o : scene.objects) {
        if (o.name == options.object) return o;
        names += (names.empty() ? "" : ", ") + o.name;
    }
    throw InputError({"--object", 0, 0, {}}, "no object named '" + options.object + "' in " +
                                                 options.scene + " (objects: " + names + ")");
}

bool sameFile(const std::string& a, const std::string& b) {
    std::error_code ec;
    return std::filesystem::equivalent(a, b, ec);
}

// Every source line with what its work is for this binding.
void printAnnotatedSource(const ShaderAst& ast, const FactoredShader& f) {
    std::printf(
        "\nthe source for this binding (R: repeated every frame, S: static -- stored, or "
        "repeated where cheaper, B: baked, its dynamic input frozen, f: free on the "
        "frames' geometry):\n");
    std::istringstream in(ast.source);
    std::string text;
    size_t next = 0;
    for (int line = 1; std::getline(in, text); ++line) {
        std::string mark;
        if (next < f.lineStages.size() && f.lineStages[next].line == line) {
            const SourceLineStages& l = f.lineStages[next++];
            mark = std::string(l.repeated ? "R" : "") + (l.stored ? "S" : "") +
                   (l.baked ? "B" : "") + (l.free ? "f" : "");
        }
        std::printf("  %-4s %3d | %s\n", mark.c_str(), line, text.c_str());
    }
}

nlohmann::json sourceLinesJson(const ShaderAst& ast, const FactoredShader& f) {
    nlohmann::json lines = nlohmann::json::array();
    for (const SourceLineStages& l : f.lineStages)
        lines.push_back({{"line", l.line},
                         {"source", sourceLine(ast.source, l.line)},
                         {"repeated", l.repeated},
                         {"static", l.stored},
                         {"baked", l.baked},
                         {"free", l.free}});
    return lines;
}

// --json: the factoring as one document.
nlohmann::json factoringJson(const std::string& shaderFile, const ShaderAst& ast,
                             const std::string& bindingText, const FactoredShader& f,
                             double ratio) {
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
        for (const DynamicLine& l : from) {
            nlohmann::json causes = nlohmann::json::array();
            for (const DynamicCause& c : l.causes) {
                nlohmann::json cause = {
                    {"kind", c.kind}, {"why", c.why}, {"line", c.line}, {"column", c.column}};
                if (!c.name.empty()) cause["name"] = c.name;
                if (c.index >= 0) cause["index"] = c.index;
                causes.push_back(std::move(cause));
            }
            lines.push_back({{"line", l.line},
                             {"source", sourceLine(ast.source, l.line)},
                             {"chain", l.chain},
                             {"causes", causes}});
        }
        return lines;
    };
    nlohmann::json doc = {
        {"shader", ast.name},
        {"file", shaderFile},
        {"binding", bindingText},
        {"naive_width", f.naiveWidth},
        {"chosen_width", f.chosenWidth},
        {"bytes_per_texel", {{"float", 4 * f.chosenWidth}, {"half", 2 * f.chosenWidth}}},
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
        {"baked_lines", linesJson(f.bakedLines)},
        {"source_lines", sourceLinesJson(ast, f)},
        {"warnings", f.warnings}};
    return doc;
}

// The factoring for a reader: the n-tuple's channels, the costs, the dynamic lines with
// what reaches them, and with --dump both parts.
void printFactoring(const FactorCommandOptions& options, const std::string& shaderFile,
                    const ShaderAst& ast, const std::string& bindingText, const FactoredShader& f,
                    double ratio, int storeAboveCost) {
    std::printf("%s (%s), factored for %s\n\n", ast.name.c_str(), shaderFile.c_str(),
                bindingText.c_str());
    std::printf("n-tuple: %d float%s (storing every static value a dynamic operation reads: %d)\n",
                f.chosenWidth, f.chosenWidth == 1 ? "" : "s", f.naiveWidth);
    if (f.chosenWidth > 0)
        std::printf(
            "  in a shader map: %d bytes a texel as float32, %d as binary16 "
            "(\"shadermap_precision\": \"half\"), plus a 1-texel border around each "
            "16x16 tile\n",
            4 * f.chosenWidth, 2 * f.chosenWidth);
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
            if (l.causes.size() > 1) {
                std::string all;
                for (const DynamicCause& c : l.causes)
                    all += (all.empty() ? "" : "; ") + c.why + " (line " + std::to_string(c.line) +
                           ":" + std::to_string(c.column) + ")";
                std::printf("        every input: %s\n", all.c_str());
            }
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
    if (!f.warnings.empty()) {
        std::printf("\nwarnings:\n");
        for (const std::string& w : f.warnings)
            std::printf("  %s:%s\n", shaderFile.c_str(), w.c_str());
    }
    printAnnotatedSource(ast, f);
    if (options.dump) {
        std::printf("\nstatic part:\n%s\ndynamic part:\n%s", f.staticPart.dump().c_str(),
                    f.dynamicPart.dump().c_str());
    }
}

}  // namespace

namespace {

// --verify: the factored shader against the whole one, output by output.
void printVerification(const SplitVerification& v, double tolerance) {
    std::printf(
        "\nverified: %d points over the charts x %d frames, static part run at the "
        "first, against the whole shader\n",
        v.points, v.frames);
    std::printf("  %-12s %12s %12s %12s   %s\n", "", "max abs", "max relative", "rms",
                "worst at (frame, chart, u, v)");
    auto row = [](const SplitDifference& d) {
        std::printf("  %-12s %12.3g %12.3g %12.3g   %d, %d, %.4f, %.4f\n", d.name.c_str(), d.maxAbs,
                    d.maxRelative, d.rms, d.worst.frame, d.worst.chart, d.worst.u, d.worst.v);
    };
    for (const SplitDifference& d : v.outputs) row(d);
    if (!v.channels.empty()) {
        std::printf(
            "  stored channels, against the static part run at each frame (0 unless a "
            "bake() froze an input):\n");
        for (const SplitDifference& d : v.channels) row(d);
    }
    std::printf("  %s --tolerance %g (largest relative difference %.3g)\n",
                v.maxRelative() <= tolerance ? "within" : "OVER", tolerance, v.maxRelative());
}

nlohmann::json verificationJson(const SplitVerification& v, double tolerance) {
    auto rows = [](const std::vector<SplitDifference>& from) {
        nlohmann::json out = nlohmann::json::array();
        for (const SplitDifference& d : from)
            out.push_back({{"name", d.name},
                           {"max_abs", d.maxAbs},
                           {"max_relative", d.maxRelative},
                           {"rms", d.rms},
                           {"worst",
                            {{"frame", d.worst.frame},
                             {"chart", d.worst.chart},
                             {"u", d.worst.u},
                             {"v", d.worst.v}}}});
        return out;
    };
    return {{"points", v.points},
            {"frames", v.frames},
            {"outputs", rows(v.outputs)},
            {"channels", rows(v.channels)},
            {"max_relative", v.maxRelative()},
            {"tolerance", tolerance},
            {"within", v.maxRelative() <= tolerance}};
}

// The binding with the command's --store and --repeat what-ifs added.
ShaderBinding withWhatIfs(const ShaderBinding& binding, const FactorCommandOptions& options) {
    ShaderBinding b = binding;
    auto add = [&](const std::vector<std::string>& from, FactoringOverride::Kind kind,
                   const char* flag) {
        for (const std::string& text : from) {
            FactoringOverride o;
            if (!parseFactoringOverride(text, kind, o))
                throw InputError({flag, 0, 0, {}},
                                 "expected line:column or a variable's name, found '" + text + "'");
            b.overrides.push_back(o);
        }
    };
    add(options.store, FactoringOverride::Kind::Store, "--store");
    add(options.repeat, FactoringOverride::Kind::Repeat, "--repeat");
    return b;
}

// One factoring, printed or added to `json`.
FactoredShader factorOne(const FactorCommandOptions& options, const std::string& shaderFile,
                         const ShaderAst& ast, const ShaderBinding& binding,
                         const std::string& bindingText, nlohmann::json* json) {
    FactorOptions factorOptions;
    factorOptions.storeAboveCost = options.storeAboveCost;
    const ShaderBinding asked = withWhatIfs(binding, options);
    const FactoredShader f = factorShader(ast, asked, factorOptions);
    const double ratio =
        f.staticInstructions > 0 ? double(f.dynamicInstructions) / f.staticInstructions : 0.0;
    if (json)
        *json = factoringJson(shaderFile, ast, bindingText, f, ratio);
    else
        printFactoring(options, shaderFile, ast, bindingText, f, ratio,
                       factorOptions.storeAboveCost);
    if (asked.overrides.size() > binding.overrides.size()) {
        // The what-if against the split without it.
        const FactoredShader base = factorShader(ast, binding, factorOptions);
        if (json) {
            (*json)["what_if"] = {{"without",
                                   {{"chosen_width", base.chosenWidth},
                                    {"static_cost", base.staticCost},
                                    {"dynamic_cost", base.dynamicCost}}}};
        } else {
            std::printf("\nwhat-if, against the split without it:\n");
            std::printf("  %-16s %8d -> %d\n", "n-tuple floats", base.chosenWidth, f.chosenWidth);
            std::printf("  %-16s %8d -> %d\n", "bytes a texel", 4 * base.chosenWidth,
                        4 * f.chosenWidth);
            std::printf("  %-16s %8d -> %d\n", "static cost", base.staticCost, f.staticCost);
            std::printf("  %-16s %8d -> %d\n", "dynamic cost", base.dynamicCost, f.dynamicCost);
        }
    }
    return f;
}

// The scene's objects grouped by splits alike -- the same shader cut the same way (stored
// channels, instructions and costs of each part), whatever constants their parameters
// folded in: twelve pebbles of one shader in twelve colours are one row.
struct SplitGroup {
    std::string key, shader;
    std::vector<std::string> objects;
    int channels = 0, bytesPerTexel = 0, staticCost = 0, dynamicCost = 0;
};

void addToGroups(std::vector<SplitGroup>& groups, const SceneObject& object,
                 const FactoredShader& f) {
    const std::string key = object.shader->file + " " + std::to_string(f.chosenWidth) + " " +
                            std::to_string(f.staticInstructions) + " " +
                            std::to_string(f.dynamicInstructions) + " " +
                            std::to_string(f.staticCost) + " " + std::to_string(f.dynamicCost) +
                            " " + std::to_string(object.shadermapHalf);
    for (SplitGroup& g : groups)
        if (g.key == key) {
            g.objects.push_back(object.name);
            return;
        }
    SplitGroup g;
    g.key = key;
    g.shader = object.shader->name;
    g.objects = {object.name};
    g.channels = f.chosenWidth;
    g.bytesPerTexel = f.chosenWidth * (object.shadermapHalf ? 2 : 4);
    g.staticCost = f.staticCost;
    g.dynamicCost = f.dynamicCost;
    groups.push_back(std::move(g));
}

void printGroups(const std::vector<SplitGroup>& groups, size_t objects) {
    std::printf("\n====\n\nthe scene: %zu objects, %zu kinds of split\n", objects, groups.size());
    std::printf("  %-32s %-16s %8s %10s %12s %13s\n", "objects", "shader", "floats", "bytes/texel",
                "static cost", "dynamic cost");
    long staticTotal = 0, dynamicTotal = 0;
    for (const SplitGroup& g : groups) {
        std::string names = g.objects.front();
        if (g.objects.size() > 1) names += " and " + std::to_string(g.objects.size() - 1) + " more";
        std::printf("  %-32s %-16s %8d %10d %12d %13d\n", names.c_str(), g.shader.c_str(),
                    g.channels, g.bytesPerTexel, g.staticCost, g.dynamicCost);
        staticTotal += static_cast<long>(g.staticCost) * static_cast<long>(g.objects.size());
        dynamicTotal += static_cast<long>(g.dynamicCost) * static_cast<long>(g.objects.size());
    }
    std::printf("  summed over the objects, cost units a point: static %ld, dynamic %ld\n",
                staticTotal, dynamicTotal);
}

nlohmann::json groupsJson(const std::vector<SplitGroup>& groups) {
    nlohmann::json out = nlohmann::json::array();
    for (const SplitGroup& g : groups)
        out.push_back({{"objects", g.objects},
                       {"shader", g.shader},
                       {"channels", g.channels},
                       {"bytes_per_texel", g.bytesPerTexel},
                       {"static_cost", g.staticCost},
                       {"dynamic_cost", g.dynamicCost}});
    return out;
}

}  // namespace

int runFactorCommand(const FactorCommandOptions& options) {
    if (options.scene.empty()) {
        if (!options.object.empty())
            throw InputError({"--object", 0, 0, {}}, "--object needs --scene");
        if (options.verify)
            throw InputError({"--verify", 0, 0, {}},
                             "--verify needs --scene (its objects' charts and frames)");
        if (options.shader.empty())
            throw InputError({"factor", 0, 0, {}},
                             "give a shader file, --scene SCENE (every object) or --scene SCENE "
                             "--object NAME");
        auto ast = loadShaderFile(options.shader);
        nlohmann::json doc;
        factorOne(options, options.shader, *ast, defaultBinding(),
                  "parameters at their defaults, a fixed ambient and a fixed distant light",
                  options.json ? &doc : nullptr);
        if (options.json) std::printf("%s\n", doc.dump(2).c_str());
        return 0;
    }
    Scene scene = loadScene(options.scene);
    std::vector<size_t> objects;
    if (!options.object.empty()) {
        const SceneObject& object = findObject(scene, options);
        objects.push_back(static_cast<size_t>(&object - scene.objects.data()));
        // A shader file that is not the object's is factored (and verified) on its binding
        // instead: a what-if, said so.
        if (!options.shader.empty()) {
            auto ast = loadShaderFile(options.shader);
            objectBinding(scene, object, *ast, options.shader);
            if (!sameFile(options.shader, object.shader->file))
                std::fprintf(stderr,
                             "mpshade: note: object '%s' uses %s; factoring %s on its binding "
                             "instead\n",
                             object.name.c_str(), object.shader->file.c_str(),
                             options.shader.c_str());
            scene.objects[objects[0]].shader = ast;
        }
    } else if (!options.shader.empty()) {
        throw InputError({"--scene", 0, 0, {}},
                         "--scene with a shader file needs --object NAME (without a shader "
                         "file: every object, each with its own shader)");
    } else {
        for (size_t i = 0; i < scene.objects.size(); ++i) objects.push_back(i);
    }
    // The shading the renderers would use, for --verify.
    std::unique_ptr<SceneResources> resources;
    std::unique_ptr<StaticPhase> statics;
    if (options.verify) {
        resources =
            std::make_unique<SceneResources>(scene, SceneResources::RayScenes::ForOcclusion);
        StaticPhaseOptions so;
        so.factor.storeAboveCost = options.storeAboveCost;
        statics = std::make_unique<StaticPhase>(scene, *resources, so);
    }
    bool within = true;
    nlohmann::json all = nlohmann::json::array();
    std::vector<SplitGroup> groups;
    for (size_t k = 0; k < objects.size(); ++k) {
        const SceneObject& object = scene.objects[objects[k]];
        const std::string file = options.shader.empty() ? object.shader->file : options.shader;
        if (k > 0 && !options.json) std::printf("\n----\n\n");
        nlohmann::json doc;
        const FactoredShader f = factorOne(
            options, file, *object.shader, objectBinding(scene, object, *object.shader, file),
            "object '" + object.name + "' in " + options.scene, options.json ? &doc : nullptr);
        addToGroups(groups, object, f);
        if (statics) {
            const SplitVerification v = verifySplit(*statics, *resources, objects[k]);
            within = within && v.maxRelative() <= options.tolerance;
            if (options.json)
                doc["verify"] = verificationJson(v, options.tolerance);
            else
                printVerification(v, options.tolerance);
        }
        if (options.json) {
            if (options.object.empty()) doc["object"] = object.name;
            all.push_back(std::move(doc));
        }
    }
    if (options.json) {
        const nlohmann::json out =
            options.object.empty()
                ? nlohmann::json{{"objects", all}, {"splits", groupsJson(groups)}}
                : all[0];
        std::printf("%s\n", out.dump(2).c_str());
    } else if (options.object.empty()) {
        printGroups(groups, objects.size());
    }
    return within ? 0 : 1;
}

}  // namespace mpshade
