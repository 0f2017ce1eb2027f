// scene_loader.cpp -- the scene file reader (docs/scene-format.md is the contract).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>

#include <nlohmann/json.hpp>

#include "geometry/content_digest.h"
#include "scene/json_reader.h"
#include "scene/scene.h"
#include "scene/variability.h"
#include "shading/lower.h"
#include "shading/shader_compiler.h"

namespace mpshade {
namespace {

namespace fs = std::filesystem;

// Keys: a non-empty array of { "t": seconds, ...fields } with strictly increasing t.
// `read` is called for each key with the key node, after "t" is validated.
template <typename F>
void readKeys(const JsonNode& keys, std::initializer_list<const char*> fields, F&& read) {
    const size_t n = keys.size();
    if (n == 0) keys.fail("expected at least one key");
    float previous = -INFINITY;
    for (size_t i = 0; i < n; ++i) {
        JsonNode key = keys.at(i);
        std::vector<const char*> allowed{"t"};
        allowed.insert(allowed.end(), fields.begin(), fields.end());
        if (!key.isObject()) key.fail("expected a key object { \"t\": seconds, ... }");
        key.allowKeys(allowed);
        const float t = static_cast<float>(key["t"].number());
        if (!(t > previous))
            key["t"].fail("keys must be sorted by strictly increasing t (previous key has t = " +
                          shortNumber(previous) + ")");
        previous = t;
        read(key, t);
    }
}

template <typename T, typename Get>
void addKey(Keyframes<T>& frames, const JsonNode& key, const char* field, float t, Get get) {
    if (auto node = key.optional(field)) {
        frames.times.push_back(t);
        frames.values.push_back(get(*node));
    }
}

// Positions and lengths mpshade renders correctly: everything is float, and ray queries
// need every object-space coordinate (the eye seen from an object included) well inside
// the ray tracer's valid range (about 1.8e18): positions within 1e8 of the origin, scales
// and sizes in [1e-8, 1e8] keep the eye within 2e16 in any object's coordinates.
constexpr double kMaxCoordinate = 1e8;
constexpr double kMinLength = 1e-8, kMaxLength = 1e8;

std::string limitText(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    std::string text = buf;  // 1e+08 -> 1e8, 1e-08 -> 1e-8
    for (const char* from : {"e+0", "e+", "e-0"})
        if (auto at = text.find(from); at != std::string::npos)
            text.replace(at, std::strlen(from), from[1] == '-' ? "e-" : "e");
    return text;
}

glm::vec3 positionOf(const JsonNode& n) {
    const glm::vec3 v = n.vec3();
    for (int c = 0; c < 3; ++c)
        if (!(std::fabs(v[c]) <= kMaxCoordinate))
            n.fail("coordinates must be within " + limitText(kMaxCoordinate) +
                   " of the origin (found " + limitText(v[c]) + ")");
    return v;
}
double lengthOf(const JsonNode& n) {
    const double v = n.positive();
    if (!(v >= kMinLength && v <= kMaxLength))
        n.fail("expected a length in [" + limitText(kMinLength) + ", " + limitText(kMaxLength) +
               "], found " + limitText(v));
    return v;
}
glm::vec3 colorOf(const JsonNode& n) {
    glm::vec3 c = n.vec3();
    if (c.x < 0 || c.y < 0 || c.z < 0) n.fail("color components must be non-negative");
    // -0 as +0: a light's terms are then never -0, which the shaders' light sums rely on
    // to start from their first light (shading/lower.cpp).
    return c + glm::vec3(0.0f);
}
glm::vec3 directionOf(const JsonNode& n) {
    glm::vec3 d = n.vec3();
    if (!(d.x * d.x + d.y * d.y + d.z * d.z > 0.0f)) n.fail("a direction must not be zero");
    return d;
}
glm::vec4 rotationOf(const JsonNode& n) {
    if (!n.isArray() || n.size() != 4) n.fail("expected [axis_x, axis_y, axis_z, degrees]");
    glm::vec4 r(static_cast<float>(n.at(0).number()), static_cast<float>(n.at(1).number()),
                static_cast<float>(n.at(2).number()), static_cast<float>(n.at(3).number()));
    if (!(r.x * r.x + r.y * r.y + r.z * r.z > 0.0f)) n.fail("the rotation axis must not be zero");
    return r;
}
float scaleOf(const JsonNode& n) {
    if (n.isArray())
        n.fail("scale must be one positive number (mpshade supports uniform scale only)");
    return static_cast<float>(lengthOf(n));
}

template <typename T>
Keyframes<T> constant(T value) {
    Keyframes<T> k;
    k.times.push_back(0.0f);
    k.values.push_back(value);
    return k;
}

class SceneLoader {
  public:
    explicit SceneLoader(const std::string& path)
        : path_(path), dir_(fs::path(path).parent_path()) {}

    Scene loadAll() {
        const nlohmann::json doc = parseJsonFile(path_);
        JsonNode root(doc, path_, "");
        if (!root.isObject()) root.fail("a scene must be a JSON object");
        root.allowKeys({"settings", "camera", "lights", "shaders", "objects"});
        scene_.file = path_;
        if (auto s = root.optional("settings")) settings(*s);
        camera(root["camera"]);
        if (auto l = root.optional("lights")) {
            for (size_t i = 0; i < l->size(); ++i) light(l->at(i));
        }
        shaders(root["shaders"]);
        JsonNode objects = root["objects"];
        if (objects.size() == 0) objects.fail("the scene has no objects");
        for (size_t i = 0; i < objects.size(); ++i) object(objects.at(i));
        return std::move(scene_);
    }

  private:
    std::string resolve(const std::string& relative) const {
        fs::path p(relative);
        return (p.is_absolute() ? p : dir_ / p).lexically_normal().string();
    }

    std::string existingFile(const JsonNode& node) const {
        const std::string rel = node.string();
        if (rel.empty()) node.fail("expected a file path, found an empty string");
        const std::string full = resolve(rel);
        std::error_code ec;
        if (fs::is_directory(full, ec))
            node.fail("'" + rel + "' is a folder, not a file (" + full + ")");
        if (!fs::is_regular_file(full, ec))
            node.fail("file '" + rel + "' not found (looked for " + full + ")");
        return full;
    }

    // Errors inside a file that a JSON value names (a mesh, a shader) keep their own
    // file:line:col and say which value loaded the file.
    template <typename F>
    static auto withContext(const JsonNode& node, F&& load) {
        try {
            return load();
        } catch (const InputError& e) {
            if (e.where().file == node.file()) throw;
            throw InputError(e.where(),
                             e.message() + " (loading " + node.path() + " of " + node.file() + ")");
        }
    }

    void settings(const JsonNode& s) {
        s.allowKeys({"width", "height", "fps", "duration", "samples_per_pixel", "background",
                     "shading_rate"});
        RenderSettings& r = scene_.settings;
        if (auto n = s.optional("width")) r.width = n->integer(1, 16384);
        if (auto n = s.optional("height")) r.height = n->integer(1, 16384);
        if (auto n = s.optional("fps")) r.fps = static_cast<float>(n->positive());
        if (auto n = s.optional("duration")) r.duration = static_cast<float>(n->positive());
        if (auto n = s.optional("samples_per_pixel")) r.samplesPerPixel = n->integer(1, 1024);
        if (auto n = s.optional("background")) r.background = colorOf(*n);
        if (auto n = s.optional("shading_rate")) {
            const std::string rate = n->string();
            if (rate == "sample")
                r.shadingRate = ShadingRate::Sample;
            else if (rate == "pixel")
                r.shadingRate = ShadingRate::Pixel;
            else if (rate == "quad")
                r.shadingRate = ShadingRate::Quad;
            else
                n->fail("unknown shading_rate '" + rate + "' (expected sample, pixel or quad)");
        }
        if (r.fps > 1000.0f) s["fps"].fail("fps must be at most 1000");
        if (r.duration * r.fps > 1.0e6f)
            s["duration"].fail("duration * fps exceeds a million frames");
    }

    void camera(const JsonNode& c) {
        c.allowKeys({"fov_y", "near", "far", "keys", "eye", "target", "up"});
        Camera& cam = scene_.camera;
        if (auto n = c.optional("fov_y")) {
            cam.fovY = static_cast<float>(n->number());
            if (!(cam.fovY > 0.0f && cam.fovY < 180.0f))
                n->fail("fov_y must be in (0, 180) degrees");
        }
        if (auto n = c.optional("near")) cam.zNear = static_cast<float>(n->positive());
        if (auto n = c.optional("far")) cam.zFar = static_cast<float>(n->positive());
        if (!(cam.zFar > cam.zNear))
            c.fail("far (" + shortNumber(cam.zFar) + ") must exceed near (" +
                   shortNumber(cam.zNear) + ")");
        if (auto k = c.optional("keys")) {
            readKeys(*k, {"eye", "target", "up"}, [&](const JsonNode& key, float t) {
                addKey(cam.eye, key, "eye", t, positionOf);
                addKey(cam.target, key, "target", t, positionOf);
                addKey(cam.up, key, "up", t, directionOf);
            });
        }
        if (auto n = c.optional("eye")) {
            const glm::vec3 value = positionOf(*n);
            if (cam.eye.empty()) cam.eye = constant(value);  // keys override
        }
        if (auto n = c.optional("target")) {
            const glm::vec3 value = positionOf(*n);
            if (cam.target.empty()) cam.target = constant(value);  // keys override
        }
        if (auto n = c.optional("up")) {
            const glm::vec3 value = directionOf(*n);
            if (cam.up.empty()) cam.up = constant(value);  // keys override
        }
        if (cam.eye.empty()) c.fail("the camera needs an 'eye' (directly or in keys)");
        if (cam.target.empty()) c.fail("the camera needs a 'target' (directly or in keys)");
        if (cam.up.empty()) cam.up = constant(glm::vec3(0, 1, 0));
        // The view direction must be defined at every key time.
        for (float t : cam.eye.times) {
            const glm::vec3 d = cam.target.at(t) - cam.eye.at(t);
            if (!(d.x * d.x + d.y * d.y + d.z * d.z > 0.0f))
                c.fail("eye and target coincide at t = " + shortNumber(t));
        }
    }

    void light(const JsonNode& l) {
        const std::string type = l["type"].string();
        Light light;
        std::vector<const char*> fields;
        if (type == "ambient") {
            light.kind = LightKind::Ambient;
            l.allowKeys({"type", "color", "intensity", "keys"});
            fields = {"color", "intensity"};
        } else if (type == "distant") {
            light.kind = LightKind::Distant;
            l.allowKeys({"type", "color", "intensity", "direction", "keys"});
            fields = {"color", "intensity", "direction"};
        } else if (type == "point") {
            light.kind = LightKind::Point;
            l.allowKeys({"type", "color", "intensity", "position", "keys"});
            fields = {"color", "intensity", "position"};
        } else {
            l["type"].fail("unknown light type '" + type +
                           "' (expected ambient, distant or point)");
        }
        auto intensityOf = [](const JsonNode& n) { return static_cast<float>(n.nonNegative()); };
        if (auto k = l.optional("keys")) {
            const bool hasDir = light.kind == LightKind::Distant,
                       hasPos = light.kind == LightKind::Point;
            std::initializer_list<const char*> ambientFields{"color", "intensity"};
            std::initializer_list<const char*> distantFields{"color", "intensity", "direction"};
            std::initializer_list<const char*> pointFields{"color", "intensity", "position"};
            readKeys(*k, hasDir ? distantFields : (hasPos ? pointFields : ambientFields),
                     [&](const JsonNode& key, float t) {
                         addKey(light.color, key, "color", t, colorOf);
                         addKey(light.intensity, key, "intensity", t, intensityOf);
                         if (hasPos) addKey(light.position, key, "position", t, positionOf);
                         if (hasDir) addKey(light.direction, key, "direction", t, directionOf);
                     });
        }
        // As for objects, keyed fields override the light's own (scene-format.md).
        auto direct = [&](const char* field, auto& frames, auto get) {
            if (auto n = l.optional(field)) {
                const auto value = get(*n);
                if (frames.empty()) frames = constant(value);
            }
        };
        direct("color", light.color, colorOf);
        direct("intensity", light.intensity, intensityOf);
        if (light.kind == LightKind::Point) direct("position", light.position, positionOf);
        if (light.kind == LightKind::Distant) direct("direction", light.direction, directionOf);
        if (light.color.empty()) light.color = constant(glm::vec3(1.0f));
        if (light.intensity.empty()) light.intensity = constant(1.0f);
        if (light.kind == LightKind::Point && light.position.empty())
            l.fail("a point light needs a 'position'");
        if (light.kind == LightKind::Distant && light.direction.empty())
            l.fail("a distant light needs a 'direction'");
        scene_.lights.push_back(std::move(light));
    }

    void shaders(const JsonNode& s) {
        if (!s.isObject()) s.fail("expected an object mapping shader names to .sl files");
        for (auto it = s.raw().begin(); it != s.raw().end(); ++it) {
            JsonNode entry(*it, s.file(), s.path() + "." + it.key());
            const std::string file = existingFile(entry);
            scene_.shaders[it.key()] = withContext(entry, [&] { return loadShaderFile(file); });
        }
    }

    // Equal shapes share one surface, and so one ray scene and one tessellation: a scene
    // of 20,000 equal spheres holds one.
    static std::string exactKey(float v) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%a", static_cast<double>(v));
        return buf;
    }

    // `shape` says the type and its numbers; `file`, if any, holds the rest, and its bytes
    // (not its name) enter the digest, so an edited file gives a new one.
    std::shared_ptr<const Surface> surfaceFor(const std::string& shape, const std::string& file,
                                              auto make) {
        const std::string key = shape + ":" + file;
        auto it = surfaces_.find(key);
        if (it != surfaces_.end()) {
            digest_ = digests_[key];
            return it->second;
        }
        auto surface = std::make_shared<const Surface>(make());
        ContentHasher hasher;
        hasher.addString(shape);
        if (!file.empty()) hasher.addDigest(digestFile(file));
        digest_ = digests_[key] = hasher.finish();
        surfaces_[key] = surface;
        return surface;
    }

    std::shared_ptr<const Surface> geometry(const JsonNode& g, std::string& typeName) {
        const std::string type = g["type"].string();
        typeName = type;
        if (type == "sphere") {
            g.allowKeys({"type", "radius"});
            const float radius = static_cast<float>(lengthOf(g["radius"]));
            return surfaceFor("sphere:" + exactKey(radius), "",
                              [&] { return Surface(Sphere{radius}); });
        }
        if (type == "torus") {
            g.allowKeys({"type", "major", "minor"});
            const float major = static_cast<float>(lengthOf(g["major"]));
            const float minor = static_cast<float>(lengthOf(g["minor"]));
            if (!(minor < major))
                g["minor"].fail("minor must be smaller than major (a self-intersecting torus)");
            return surfaceFor("torus:" + exactKey(major) + ":" + exactKey(minor), "", [&] {
                return Surface(Torus{major, minor});
            });
        }
        if (type == "plane") {
            g.allowKeys({"type", "size"});
            JsonNode size = g["size"];
            if (!size.isArray() || size.size() != 2) size.fail("expected [width, depth]");
            const float w = static_cast<float>(lengthOf(size.at(0))),
                        d = static_cast<float>(lengthOf(size.at(1)));
            return surfaceFor("plane:" + exactKey(w) + ":" + exactKey(d), "", [&] {
                return Surface(Plane{w, d});
            });
        }
        if (type == "bezier") {
            g.allowKeys({"type", "file"});
            const std::string file = existingFile(g["file"]);
            return surfaceFor("bezier", file, [&] { return Surface(loadBezierPatches(file)); });
        }
        if (type == "subdiv") {
            g.allowKeys({"type", "file", "scheme"});
            const std::string file = existingFile(g["file"]);
            SubdivScheme scheme = SubdivScheme::Catmark;
            if (auto s = g.optional("scheme")) {
                const std::string name = s->string();
                if (name == "loop")
                    scheme = SubdivScheme::Loop;
                else if (name != "catmark")
                    s->fail("unknown scheme '" + name + "' (expected catmark or loop)");
            }
            return surfaceFor("subdiv:" + std::to_string(static_cast<int>(scheme)), file, [&] {
                return Surface(SubdivSurface(loadObjCage(file), scheme, file));
            });
        }
        if (type == "mesh") {
            g.allowKeys({"type", "file"});
            const std::string file = existingFile(g["file"]);
            return surfaceFor("mesh", file,
                              [&] { return Surface(PolygonMesh(readObjPolygons(file))); });
        }
        if (type == "points") {
            g.allowKeys({"type", "file"});
            const std::string file = existingFile(g["file"]);
            return surfaceFor("points", file, [&] { return Surface(loadPointCloud(file)); });
        }
        g["type"].fail("unknown geometry type '" + type +
                       "' (expected sphere, torus, plane, bezier, subdiv, mesh or points)");
    }

    ParamValue param(const JsonNode& n, const ParamDecl& decl) {
        ParamValue p;
        p.name = decl.name;
        p.components = componentCount(decl.type);
        auto valueOf = [&](const JsonNode& v) {
            if (p.components == 3) {
                if (v.isNumber()) return glm::vec3(static_cast<float>(v.number()));
                return v.vec3();
            }
            if (decl.type == ValueType::Int)
                return glm::vec3(static_cast<float>(v.integer(-16777216, 16777216)));
            return glm::vec3(static_cast<float>(v.number()));
        };
        if (n.isObject()) {
            n.allowKeys({"keys"});
            readKeys(n["keys"], {"value"}, [&](const JsonNode& key, float t) {
                p.value.times.push_back(t);
                p.value.values.push_back(valueOf(key["value"]));
            });
        } else {
            p.value = constant(valueOf(n));
        }
        return p;
    }

    // An object's "factoring": {"store": [...], "repeat": [...]}, each "line:column" or a
    // variable's name (checked against the shader when it is factored).
    static std::vector<FactoringOverride> factoringOverrides(const JsonNode& r) {
        r.allowKeys({"store", "repeat"});
        std::vector<FactoringOverride> out;
        for (const auto& [key, kind] : {std::pair{"store", FactoringOverride::Kind::Store},
                                        std::pair{"repeat", FactoringOverride::Kind::Repeat}})
            if (auto list = r.optional(key))
                for (size_t k = 0; k < list->size(); ++k) {
                    const JsonNode item = list->at(k);
                    FactoringOverride f;
                    if (!parseFactoringOverride(item.string(), kind, f))
                        item.fail("expected \"line:column\" or a variable's name, found '" +
                                  item.string() + "'");
                    out.push_back(f);
                }
        return out;
    }

    void object(const JsonNode& o) {
        o.allowKeys({"name", "geometry", "shader", "params", "transform", "keys", "representation",
                     "shadermap_resolution", "shadermap_precision", "factoring", "range"});
        SceneObject obj;
        obj.name = o["name"].string();
        if (obj.name.empty()) o["name"].fail("an object name must not be empty");
        for (const auto& other : scene_.objects)
            if (other.name == obj.name)
                o["name"].fail("another object is already named '" + obj.name + "'");
        obj.surface =
            withContext(o["geometry"], [&] { return geometry(o["geometry"], obj.geometryType); });
        obj.geometryDigest = digest_;
        {
            const Bounds3 b = surfaceBounds(*obj.surface);
            for (int c = 0; c < 3; ++c)
                if (!(std::fabs(b.lo[c]) <= kMaxCoordinate && std::fabs(b.hi[c]) <= kMaxCoordinate))
                    o["geometry"].fail("the geometry reaches " +
                                       limitText(std::max(std::fabs(b.lo[c]), std::fabs(b.hi[c]))) +
                                       " from its origin; coordinates must be within " +
                                       limitText(kMaxCoordinate));
        }
        obj.shaderName = o["shader"].string();
        auto sh = scene_.shaders.find(obj.shaderName);
        if (sh == scene_.shaders.end())
            o["shader"].fail("no shader named '" + obj.shaderName + "' in 'shaders'");
        obj.shader = sh->second;
        if (auto params = o.optional("params")) {
            if (!params->isObject())
                params->fail("expected an object mapping parameter names to values");
            for (auto it = params->raw().begin(); it != params->raw().end(); ++it) {
                JsonNode value(*it, params->file(), params->path() + "." + it.key());
                const ParamDecl* decl = nullptr;
                for (const auto& d : obj.shader->params)
                    if (d.name == it.key()) decl = &d;
                if (!decl) {
                    std::string list;
                    for (const auto& d : obj.shader->params)
                        list += (list.empty() ? "" : ", ") + d.name;
                    value.fail("shader '" + obj.shaderName + "' has no parameter '" + it.key() +
                               "' (it has: " + list + ")");
                }
                obj.params.push_back(param(value, *decl));
            }
        }
        ObjectTransform& tr = obj.transform;
        if (auto t = o.optional("keys")) {
            readKeys(*t, {"translate", "rotate", "scale"}, [&](const JsonNode& key, float time) {
                addKey(tr.translate, key, "translate", time, positionOf);
                addKey(tr.rotate, key, "rotate", time, rotationOf);
                addKey(tr.scale, key, "scale", time, scaleOf);
            });
        }
        if (auto t = o.optional("transform")) {
            t->allowKeys({"translate", "rotate", "scale"});
            // Keyed fields override the static transform.
            if (auto n = t->optional("translate"); n && tr.translate.empty())
                tr.translate = constant(positionOf(*n));
            if (auto n = t->optional("rotate"); n && tr.rotate.empty())
                tr.rotate = constant(rotationOf(*n));
            if (auto n = t->optional("scale"); n && tr.scale.empty())
                tr.scale = constant(scaleOf(*n));
        }
        if (tr.translate.empty()) tr.translate = constant(glm::vec3(0.0f));
        if (tr.rotate.empty()) tr.rotate = constant(glm::vec4(0, 1, 0, 0));
        if (tr.scale.empty()) tr.scale = constant(1.0f);
        if (auto r = o.optional("representation")) {
            const std::string rep = r->string();
            if (rep == "shadermap")
                obj.representation = Representation::ShaderMap;
            else if (rep == "facets")
                obj.representation = Representation::Facets;
            else if (rep == "direct")
                obj.representation = Representation::Direct;
            else if (rep != "auto")
                r->fail("unknown representation '" + rep +
                        "' (expected auto, facets, shadermap or direct)");
        }
        if (auto r = o.optional("shadermap_resolution"))
            obj.shadermapResolution = r->integer(1, 1 << 20);
        if (auto r = o.optional("shadermap_precision")) {
            const std::string precision = r->string();
            if (precision == "half")
                obj.shadermapPrecision = MapPrecision::Half;
            else if (precision == "float")
                obj.shadermapPrecision = MapPrecision::Float;
            else if (precision != "auto")
                r->fail("unknown precision '" + precision + "' (expected auto, float or half)");
        }
        if (auto r = o.optional("factoring")) obj.factoring = factoringOverrides(*r);
        if (auto r = o.optional("range")) {
            r->allowKeys({"distance_factor", "angle"});
            if (auto d = r->optional("distance_factor")) {
                obj.range.distanceFactor = static_cast<float>(d->number());
                if (!(obj.range.distanceFactor > 1.0f)) d->fail("distance_factor must exceed 1");
            }
            if (auto a = r->optional("angle")) {
                obj.range.angle = static_cast<float>(a->number());
                if (!(obj.range.angle > 0.0f && obj.range.angle <= 180.0f))
                    a->fail("angle must be in (0, 180] degrees");
            }
        }
        scene_.objects.push_back(std::move(obj));
        // The shader must specialize for this binding: an animated parameter it needs
        // constant (a loop bound, an octave or ray count) is this object's error.
        try {
            lowerShader(*scene_.objects.back().shader, bindingOf(scene_, scene_.objects.back()));
        } catch (const InputError& e) {
            throw InputError(e.where(), e.message() + " (binding " + o.path() + " '" +
                                            scene_.objects.back().name + "' of " + o.file() + ")");
        }
    }

    std::string path_;
    fs::path dir_;
    Scene scene_;
    std::map<std::string, std::shared_ptr<const Surface>> surfaces_;
    std::map<std::string, Digest128> digests_;
    Digest128 digest_;  // the last geometry()'s
};

}  // namespace

int Scene::frameCount() const {
    return std::max(1, static_cast<int>(std::ceil(settings.duration * settings.fps - 1e-4f)));
}

Scene loadScene(const std::string& path) {
    return SceneLoader(path).loadAll();
}

}  // namespace mpshade
