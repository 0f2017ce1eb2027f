#include "app/factor_command.h"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "app/factor_measures.h"
#include "controller/multiphase_options.h"
#include "geometry/error.h"
#include "phases/map_demand.h"
#include "phases/scene_resources.h"
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

// What the scene's frames ask of a binding's shader map (phases/map_demand.h).
struct BoundMap {
    MapDemand demand;
    bool half = false;            // the object's "shadermap_precision", or what auto chooses
    std::string precisionReason;  // auto: why (map_precision.h); empty: set by the scene
};

void printMapDemand(const BoundMap& map, int floats) {
    const MapDemand& d = map.demand;
    const char* precision = map.half ? "binary16" : "float32";
    const double pinned = d.bytes(d.pinnedTiles, floats, map.half) / 1048576.0;
    std::printf(
        "  at this scene's maps (level 0 %d texels a chart side; frames spread over the "
        "scene, hidden parts left out):\n",
        d.resolution);
    if (d.frame < 0)
        std::printf("    no frame looked at sees it");
    else
        std::printf(
            "    frame %d asks most: about %.0f tiles, down to level %d (%d texels a "
            "side), for %.0f covered pixels: %.2f MB as %s (%.2f MB as %s)",
            d.frame, d.tiles, d.finestLevel, d.resolution >> d.finestLevel, d.coveredPixels,
            d.bytes(floats, map.half) / 1048576.0, precision,
            d.bytes(floats, !map.half) / 1048576.0, map.half ? "float32" : "binary16");
    std::printf(";\n    play keeps %.0f tiles of coarse levels resident besides: %.2f MB\n",
                d.pinnedTiles, pinned);
    if (!map.precisionReason.empty())
        std::printf("  precision auto: %s\n", map.precisionReason.c_str());
}

nlohmann::json mapDemandJson(const BoundMap& map, int floats) {
    const MapDemand& d = map.demand;
    return {{"resolution", d.resolution},
            {"frame", d.frame},
            {"covered_pixels", d.coveredPixels},
            {"tiles", d.tiles},
            {"pinned_tiles", d.pinnedTiles},
            {"finest_level", d.finestLevel},
            {"precision", map.half ? "half" : "float"},
            {"precision_reason", map.precisionReason},
            {"bytes", d.bytes(floats, map.half)},
            {"pinned_bytes", d.bytes(d.pinnedTiles, floats, map.half)}};
}

// The factoring for a reader: the n-tuple's channels, the costs, the dynamic lines with
// what reaches them, and with --dump both parts.
void printFactoring(const FactorCommandOptions& options, const std::string& shaderFile,
                    const ShaderAst& ast, const std::string& bindingText, const FactoredShader& f,
                    double ratio, int storeAboveCost, const BoundMap* map) {
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
    if (f.chosenWidth > 0 && map) printMapDemand(*map, f.chosenWidth);
    if (f.recomputedStaticCost > 0)
        std::printf(
            "  %s: %d cost units of static work a point, cheaper to repeat than "
            "to read back (--store-above-cost %d), run by the dynamic part\n",
            f.chosenWidth == 0 ? "nothing stored" : "some not stored", f.recomputedStaticCost,
            storeAboveCost);
    const bool perChannelBytes = map && map->demand.frame >= 0;
    if (!f.channels.empty())
        std::printf("  %-9s %-7s %-18s %s%s\n", "channel", "type", "holds",
                    perChannelBytes ? "  MB at that frame  " : "", "computed at");
    for (size_t k = 0; k < f.channels.size();) {
        const int group = groupSize(f.channels, k);
        const ChannelInfo& c = f.channels[k];
        const std::string index =
            group == 3 ? std::to_string(k) + "-" + std::to_string(k + 2) : std::to_string(k);
        const char* type = group == 3 ? typeName(c.type) : "float";
        std::string mb;
        if (perChannelBytes) {
            char text[32];
            std::snprintf(text, sizeof text, "  %17.2f  ",
                          map->demand.bytes(group, map->half) / 1048576.0);
            mb = text;
        }
        std::printf("  %-9s %-7s %-18s %sline %d:%d  %s\n", index.c_str(), type,
                    channelLabel(c, group).c_str(), mb.c_str(), c.line, c.column,
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

// One factoring, printed or added to `json`; with a what-if, `without` (when set) gets the
// split without it.
FactoredShader factorOne(const FactorCommandOptions& options, const std::string& shaderFile,
                         const ShaderAst& ast, const ShaderBinding& binding,
                         const std::string& bindingText, const BoundMap* map, nlohmann::json* json,
                         std::optional<FactoredShader>* without = nullptr) {
    FactorOptions factorOptions;
    factorOptions.storeAboveCost = options.storeAboveCost;
    const ShaderBinding asked = withWhatIfs(binding, options);
    const FactoredShader f = factorShader(ast, asked, factorOptions);
    const double ratio =
        f.staticInstructions > 0 ? double(f.dynamicInstructions) / f.staticInstructions : 0.0;
    if (json) {
        *json = factoringJson(shaderFile, ast, bindingText, f, ratio);
        if (map && f.chosenWidth > 0) (*json)["map_estimate"] = mapDemandJson(*map, f.chosenWidth);
    } else {
        printFactoring(options, shaderFile, ast, bindingText, f, ratio,
                       factorOptions.storeAboveCost, map);
    }
    if (asked.overrides.size() > binding.overrides.size()) {
        // The what-if against the split without it.
        FactoredShader base = factorShader(ast, binding, factorOptions);
        if (json) {
            (*json)["what_if"] = {{"without",
                                   {{"chosen_width", base.chosenWidth},
                                    {"static_cost", base.staticCost},
                                    {"dynamic_cost", base.dynamicCost}}}};
            if (map)
                (*json)["what_if"]["without"]["map_bytes"] =
                    map->demand.bytes(base.chosenWidth, map->half);
        } else {
            std::printf("\nwhat-if, against the split without it:\n");
            std::printf("  %-16s %8d -> %d\n", "n-tuple floats", base.chosenWidth, f.chosenWidth);
            const int texel = map && map->half ? 2 : 4;
            std::printf("  %-16s %8d -> %d\n", "bytes a texel", texel * base.chosenWidth,
                        texel * f.chosenWidth);
            if (map)
                std::printf("  %-16s %8.2f -> %.2f\n", "map MB",
                            map->demand.bytes(base.chosenWidth, map->half) / 1048576.0,
                            map->demand.bytes(f.chosenWidth, map->half) / 1048576.0);
            std::printf("  %-16s %8d -> %d\n", "static cost", base.staticCost, f.staticCost);
            std::printf("  %-16s %8d -> %d\n", "dynamic cost", base.dynamicCost, f.dynamicCost);
        }
        if (without) *without = std::move(base);
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
    double mapBytes = 0.0;  // estimated, summed over the objects (each at its busiest frame)
};

void addToGroups(std::vector<SplitGroup>& groups, const SceneObject& object,
                 const FactoredShader& f, const BoundMap& map) {
    const double bytes = f.chosenWidth > 0 ? map.demand.bytes(f.chosenWidth, map.half) : 0.0;
    const std::string key = object.shader->file + " " + std::to_string(f.chosenWidth) + " " +
                            std::to_string(f.staticInstructions) + " " +
                            std::to_string(f.dynamicInstructions) + " " +
                            std::to_string(f.staticCost) + " " + std::to_string(f.dynamicCost) +
                            " " + std::to_string(map.half);
    for (SplitGroup& g : groups)
        if (g.key == key) {
            g.objects.push_back(object.name);
            g.mapBytes += bytes;
            return;
        }
    SplitGroup g;
    g.key = key;
    g.shader = object.shader->name;
    g.objects = {object.name};
    g.channels = f.chosenWidth;
    g.bytesPerTexel = f.chosenWidth * (map.half ? 2 : 4);
    g.staticCost = f.staticCost;
    g.dynamicCost = f.dynamicCost;
    g.mapBytes = bytes;
    groups.push_back(std::move(g));
}

void printGroups(const std::vector<SplitGroup>& groups, size_t objects) {
    std::printf("\n====\n\nthe scene: %zu objects, %zu kinds of split\n", objects, groups.size());
    std::printf("  %-32s %-16s %8s %10s %12s %13s %10s\n", "objects", "shader", "floats",
                "bytes/texel", "static cost", "dynamic cost", "map MB");
    long staticTotal = 0, dynamicTotal = 0;
    double mapTotal = 0.0;
    for (const SplitGroup& g : groups) {
        std::string names = g.objects.front();
        if (g.objects.size() > 1) names += " and " + std::to_string(g.objects.size() - 1) + " more";
        std::printf("  %-32s %-16s %8d %10d %12d %13d %10.2f\n", names.c_str(), g.shader.c_str(),
                    g.channels, g.bytesPerTexel, g.staticCost, g.dynamicCost,
                    g.mapBytes / 1048576.0);
        mapTotal += g.mapBytes;
        staticTotal += static_cast<long>(g.staticCost) * static_cast<long>(g.objects.size());
        dynamicTotal += static_cast<long>(g.dynamicCost) * static_cast<long>(g.objects.size());
    }
    std::printf(
        "  summed over the objects, cost units a point: static %ld, dynamic %ld; shader "
        "maps about %.2f MB (each object at the frame that asks most of it)\n",
        staticTotal, dynamicTotal, mapTotal / 1048576.0);
}

nlohmann::json groupsJson(const std::vector<SplitGroup>& groups) {
    nlohmann::json out = nlohmann::json::array();
    for (const SplitGroup& g : groups)
        out.push_back({{"objects", g.objects},
                       {"shader", g.shader},
                       {"channels", g.channels},
                       {"bytes_per_texel", g.bytesPerTexel},
                       {"static_cost", g.staticCost},
                       {"dynamic_cost", g.dynamicCost},
                       {"map_bytes", g.mapBytes}});
    return out;
}

// The frame whose maps, all objects together, ask for the most bytes at once, against the
// tile cache that holds them in a render (MultiphaseOptions::mapMemoryBytes, --cache-mb):
// over it, tiles are dropped and filled again within the frame's work.
struct BusiestFrame {
    int frame = -1;
    double bytes = 0.0;
    double cacheBytes = static_cast<double>(MultiphaseOptions{}.mapMemoryBytes);
};

void addToBusiest(std::vector<double>& byFrame, const MapDemand& d, int channels, bool half) {
    if (byFrame.size() < d.frameTiles.size()) byFrame.resize(d.frameTiles.size(), 0.0);
    for (size_t f = 0; f < d.frameTiles.size(); ++f)
        byFrame[f] += channels > 0 ? d.bytes(d.frameTiles[f], channels, half) : 0.0;
}

BusiestFrame busiestFrame(const std::vector<double>& byFrame, const MapDemand& any) {
    BusiestFrame b;
    for (size_t f = 0; f < byFrame.size() && f < any.frames.size(); ++f)
        if (byFrame[f] > b.bytes) b.frame = any.frames[f], b.bytes = byFrame[f];
    return b;
}

void printBusiest(const BusiestFrame& b) {
    if (b.frame < 0) return;
    std::printf(
        "  the frame that asks most of all the maps at once: frame %d, about %.2f MB; the "
        "tile cache holds %.0f MB (render --cache-mb)%s\n",
        b.frame, b.bytes / 1048576.0, b.cacheBytes / 1048576.0,
        b.bytes > b.cacheBytes ? ": OVER it, so tiles are dropped and filled again within "
                                 "a frame (raise --cache-mb, or store as binary16)"
                               : "");
}

// The objects `options` asks to factor: the one named (with a shader file that is not its
// own factored on its binding instead, said so) or every object of the scene.
std::vector<size_t> objectsToFactor(Scene& scene, const FactorCommandOptions& options) {
    std::vector<size_t> objects;
    if (options.object.empty()) {
        if (!options.shader.empty())
            throw InputError({"--scene", 0, 0, {}},
                             "--scene with a shader file needs --object NAME (without a shader "
                             "file: every object, each with its own shader)");
        for (size_t i = 0; i < scene.objects.size(); ++i) objects.push_back(i);
        return objects;
    }
    const SceneObject& object = findObject(scene, options);
    objects.push_back(static_cast<size_t>(&object - scene.objects.data()));
    if (!options.shader.empty()) {
        auto ast = loadShaderFile(options.shader);
        objectBinding(scene, object, *ast, options.shader);
        if (!sameFile(options.shader, object.shader->file))
            std::fprintf(stderr,
                         "mpshade: note: object '%s' uses %s; factoring %s on its binding "
                         "instead\n",
                         object.name.c_str(), object.shader->file.c_str(), options.shader.c_str());
        scene.objects[objects[0]].shader = ast;
    }
    return objects;
}

int factorShaderAlone(const FactorCommandOptions& options) {
    if (!options.object.empty()) throw InputError({"--object", 0, 0, {}}, "--object needs --scene");
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
              "parameters at their defaults, a fixed ambient and a fixed distant light", nullptr,
              options.json ? &doc : nullptr);
    if (options.json) std::printf("%s\n", doc.dump(2).c_str());
    return 0;
}

}  // namespace

int runFactorCommand(const FactorCommandOptions& options) {
    if (options.scene.empty()) return factorShaderAlone(options);
    Scene scene = loadScene(options.scene);
    const std::vector<size_t> objects = objectsToFactor(scene, options);
    // Ray scenes of all surfaces: they hide what lies behind, for the maps' estimates.
    const SceneResources resources(scene, SceneResources::RayScenes::All);
    const std::vector<MapDemand> demands = estimateMapDemands(resources, objects);
    SplitMeasures measures(scene, resources, options, objects);
    bool within = true;
    nlohmann::json all = nlohmann::json::array();
    std::vector<SplitGroup> groups;
    std::vector<double> byFrame;  // bytes the maps ask for at each frame looked at
    for (size_t k = 0; k < objects.size(); ++k) {
        const SceneObject& object = scene.objects[objects[k]];
        const std::string file = options.shader.empty() ? object.shader->file : options.shader;
        if (k > 0 && !options.json) std::printf("\n----\n\n");
        nlohmann::json doc;
        BoundMap map{demands[k], object.shadermapPrecision == MapPrecision::Half, {}};
        if (object.shadermapPrecision == MapPrecision::Auto) {
            const MapPrecisionCheck check = measures.precisionAt(objects[k], demands[k].frame);
            map.half = check.half;
            map.precisionReason = check.reason;
        }
        std::optional<FactoredShader> without;
        const FactoredShader f = factorOne(options, file, *object.shader,
                                           objectBinding(scene, object, *object.shader, file),
                                           "object '" + object.name + "' in " + options.scene, &map,
                                           options.json ? &doc : nullptr, &without);
        addToGroups(groups, object, f, map);
        addToBusiest(byFrame, demands[k], f.chosenWidth, map.half);
        within = measures.report(f, without ? &*without : nullptr, objects[k],
                                 options.json ? &doc : nullptr) &&
                 within;
        if (options.json) {
            if (options.object.empty()) doc["object"] = object.name;
            all.push_back(std::move(doc));
        }
    }
    const BusiestFrame busiest =
        demands.empty() ? BusiestFrame{} : busiestFrame(byFrame, demands.front());
    if (options.json) {
        nlohmann::json out = options.object.empty()
                                 ? nlohmann::json{{"objects", all}, {"splits", groupsJson(groups)}}
                                 : all[0];
        if (options.object.empty())
            out["busiest_frame"] = {{"frame", busiest.frame},
                                    {"map_bytes", busiest.bytes},
                                    {"cache_bytes", busiest.cacheBytes}};
        std::printf("%s\n", out.dump(2).c_str());
    } else if (options.object.empty()) {
        printGroups(groups, objects.size());
        printBusiest(busiest);
    }
    return within ? 0 : 1;
}

}  // namespace mpshade
