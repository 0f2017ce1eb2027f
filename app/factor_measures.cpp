#include "app/factor_measures.h"

#include <cstdio>

#include <nlohmann/json.hpp>

#include "geometry/error.h"
#include "phases/scene_resources.h"
#include "scene/scene.h"
#include "scene/variability.h"
#include "shading/factoring.h"

namespace mpshade {
namespace {

// The table of a split's differences from the whole shader, output by output, then stored
// channel by channel.
void printDifferences(const SplitVerification& v) {
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
}

// --verify's verdict.
void printVerdict(const SplitVerification& v, double tolerance) {
    std::printf("  %s --tolerance %g (largest relative difference %.3g)\n",
                v.maxRelative() <= tolerance ? "within" : "OVER", tolerance, v.maxRelative());
}

// Where a static run freezes what a bake() reads: the first frame verified, as a render of
// the whole sequence runs it there.
struct FrozenAt {
    int frame = 0;
    float time = 0.0f;
    glm::vec3 eye{0.0f};
};

FrozenAt frozenAt(const Scene& scene) {
    const float time = scene.frameTime(0);
    return {0, time, cameraAt(scene, time, scene.settings.width, scene.settings.height).eye};
}

nlohmann::json frozenAtJson(const FrozenAt& at) {
    return {{"frame", at.frame}, {"time", at.time}, {"eye", {at.eye.x, at.eye.y, at.eye.z}}};
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

}  // namespace

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

SplitMeasures::SplitMeasures(const Scene& scene, const SceneResources& resources,
                             const FactorCommandOptions& options,
                             const std::vector<size_t>& objects)
    : scene_(scene), resources_(resources), options_(options), objects_(objects) {
    staticOptions_.factor.storeAboveCost = options.storeAboveCost;
}

SplitMeasures::~SplitMeasures() = default;

SplitVerification SplitMeasures::asTheSceneHasIt(size_t object) {
    if (!statics_) statics_ = std::make_unique<StaticPhase>(scene_, resources_, staticOptions_);
    return verifySplit(*statics_, resources_, object);
}

MapPrecisionCheck SplitMeasures::precisionAt(size_t object, int frame) {
    if (!statics_) statics_ = std::make_unique<StaticPhase>(scene_, resources_, staticOptions_);
    const FrameState state = frameStateAt(resources_, std::max(frame, 0), scene_.settings.width,
                                          scene_.settings.height, 1);
    return checkHalfPrecision(*statics_, *scene_.objects[object].surface, object,
                              state.uniforms[object], staticOptions_.precision);
}

SplitVerification SplitMeasures::withTheWhatIf(size_t object) {
    if (!whatIfStatics_) {
        whatIfScene_ = std::make_unique<Scene>(scene_);
        for (const size_t i : objects_)
            whatIfScene_->objects[i].factoring =
                withWhatIfs(bindingOf(scene_, scene_.objects[i]), options_).overrides;
        whatIfResources_ = std::make_unique<SceneResources>(
            *whatIfScene_, SceneResources::RayScenes::ForOcclusion);
        whatIfStatics_ =
            std::make_unique<StaticPhase>(*whatIfScene_, *whatIfResources_, staticOptions_);
    }
    return verifySplit(*whatIfStatics_, *whatIfResources_, object);
}

bool SplitMeasures::report(const FactoredShader& f, const FactoredShader* without, size_t object,
                           nlohmann::json* doc) {
    const FactorCommandOptions& options = options_;
    const Scene& scene = scene_;
    const bool baked = !f.bakedLines.empty();
    if (!options.verify && !baked && !(without && !without->bakedLines.empty())) return true;
    const SplitVerification v = without ? withTheWhatIf(object) : asTheSceneHasIt(object);
    if (doc) {
        if (options.verify) (*doc)["verify"] = verificationJson(v, options.tolerance);
        if (baked)
            (*doc)["bake"] = {{"frozen_at", frozenAtJson(frozenAt(scene))},
                              {"measured", verificationJson(v, options.tolerance)}};
    } else {
        if (baked) {
            const FrozenAt at = frozenAt(scene);
            std::printf(
                "\nwhat the bakes freeze: the static run's time and view, frame %d (t = %.3f s, "
                "the eye at %.3g, %.3g, %.3g; a render starting later freezes them at its first "
                "frame, and a static run again where the re-run triggers ask). Measured at %d "
                "points over the charts x %d frames, against the whole shader:\n",
                at.frame, at.time, at.eye.x, at.eye.y, at.eye.z, v.points, v.frames);
        } else {
            std::printf(
                "\n%s: %d points over the charts x %d frames, static part run at the first, "
                "against the whole shader\n",
                options.verify ? "verified"
                               : "measured, as the split without the what-if has bakes",
                v.points, v.frames);
        }
        printDifferences(v);
        if (options.verify) printVerdict(v, options.tolerance);
    }
    if (without) {
        const SplitVerification base = asTheSceneHasIt(object);
        if (doc) {
            (*doc)["what_if"]["without"]["max_relative"] = base.maxRelative();
            (*doc)["what_if"]["with"] = {{"max_relative", v.maxRelative()}};
        } else {
            std::printf(
                "  what-if, the largest relative difference from the whole shader: "
                "%.3g without it -> %.3g with it\n",
                base.maxRelative(), v.maxRelative());
        }
    }
    return !options.verify || v.maxRelative() <= options.tolerance;
}

}  // namespace mpshade
