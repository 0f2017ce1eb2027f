// scene.h -- an evolving scene as loaded from a scene file (see docs/scene-format.md).
// Coordinates are world space, y up; angles in degrees; colors linear RGB; times seconds.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "geometry/content_digest.h"
#include "geometry/surface.h"
#include "scene/animation.h"
#include "shading/ast.h"
#include "shading/binding.h"

namespace mpshade {

// How often the dynamic shader runs: once per sub-pixel sample, or once per pixel and
// visible surface, or once per block of 2x2 pixels and visible surface, with coverage
// still per sample (docs/multiphase.md has the figures that chose the default; `play`
// lowers the rate when frames run late).
enum class ShadingRate { Sample, Pixel, Quad };

// The scene file's spelling: "sample", "pixel", "quad".
inline const char* shadingRateName(ShadingRate rate) {
    return rate == ShadingRate::Sample ? "sample" : rate == ShadingRate::Pixel ? "pixel" : "quad";
}

struct RenderSettings {
    int width = 640;             // pixels, 1..16384
    int height = 360;            // pixels, 1..16384
    float fps = 30.0f;           // frames per second, > 0
    float duration = 1.0f;       // seconds, > 0
    int samplesPerPixel = 4;     // 1..1024
    glm::vec3 background{0.0f};  // linear RGB behind everything
    ShadingRate shadingRate = ShadingRate::Sample;
};

struct Camera {
    float fovY = 40.0f;                    // vertical field of view, degrees, in (0, 180)
    float zNear = 0.05f;                   // > 0
    float zFar = 200.0f;                   // > zNear
    Keyframes<glm::vec3> eye, target, up;  // up defaults to +y
};

struct Light {
    LightKind kind = LightKind::Distant;
    Keyframes<glm::vec3> color;      // linear RGB
    Keyframes<float> intensity;      // scalar multiplier, >= 0
    Keyframes<glm::vec3> position;   // point lights
    Keyframes<glm::vec3> direction;  // distant lights: the direction the light travels
    bool animated() const {
        return color.varies() || intensity.varies() || position.varies() || direction.varies();
    }
};

struct ParamValue {
    std::string name;
    int components = 1;          // 1 (float, int) or 3
    Keyframes<glm::vec3> value;  // one key when constant; components beyond `components` unused
};

struct ObjectTransform {
    Keyframes<glm::vec3> translate;
    Keyframes<glm::vec4> rotate;  // axis xyz, angle in degrees
    Keyframes<float> scale;       // uniform, > 0
    bool animated() const { return translate.varies() || rotate.varies() || scale.varies(); }
};

// How the static phase stores an object (patent FIG. 4 and FIG. 5): facets carrying the
// n-tuple per vertex (combined), a shader map probed per sample on facets only as fine as
// the geometric error allows (separate), or whichever costs less for the frames the
// object is seen in (auto).
// How an object's static phase stores it (docs/multiphase.md): auto picks; facets carry the
// static n-tuple per vertex (combined); a shader map holds it (separate); direct stores
// nothing static and the dynamic phase runs the whole shader on facets diced to the
// geometric tolerance (for objects a stored n-tuple costs more than it saves).
enum class Representation { Auto, Facets, ShaderMap, Direct };

struct RangeOptions {
    float distanceFactor = 2.0f;  // the view distance may change by this factor
    float angle = 20.0f;          // degrees around the object
};

enum class MapPrecision { Auto, Float, Half };

struct SceneObject {
    std::string name;
    std::string geometryType;  // scene-format name
    std::shared_ptr<const Surface> surface;
    // What the surface is made from: its type, its numbers and the bytes of its file, so
    // equal digests mean equal surfaces (the shader-map store keys tiles with it).
    Digest128 geometryDigest;
    std::string shaderName;
    std::shared_ptr<const ShaderAst> shader;
    std::vector<ParamValue> params;  // only the parameters the scene binds
    ObjectTransform transform;
    Representation representation = Representation::Auto;
    int shadermapResolution = 0;  // a cap on level 0's texels per chart side; 0: the limit, 2^20
    // The shader map's channels as binary16 (shadermaps/half_float.h: relative error 2^-11,
    // finite up to 65504, half the memory) or float; Auto: binary16 where rounding to it is
    // measured not to show (phases/map_precision.h).
    MapPrecision shadermapPrecision = MapPrecision::Auto;
    // "factoring": {"store": [...], "repeat": [...]}: decisions outside the source, checked
    // against the analysis when the shader is factored (shading/binding.h).
    std::vector<FactoringOverride> factoring;
    RangeOptions range;
};

struct Scene {
    std::string file;  // as given
    RenderSettings settings;
    Camera camera;
    std::vector<Light> lights;
    std::map<std::string, std::shared_ptr<const ShaderAst>> shaders;
    std::vector<SceneObject> objects;

    // Frames cover [0, duration): frame i is at time i / fps.
    int frameCount() const;
    float frameTime(int frame) const { return static_cast<float>(frame) / settings.fps; }
};

// Loads and validates a scene with its geometry and shaders. Throws InputError naming the
// file and the JSON path (or the geometry/shader file's line) of the first problem.
Scene loadScene(const std::string& path);

}  // namespace mpshade
