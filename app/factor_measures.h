// factor_measures.h -- `mpshade factor`'s measures of a split: --verify, what a binding's
// bakes freeze and cost, and a what-if (--store, --repeat) against the split without it,
// each evaluated against the whole shader over the object's charts and frames
// (phases/split_verification.h).
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "app/factor_command.h"
#include "phases/split_verification.h"
#include "phases/static_phase.h"

namespace mpshade {

struct FactoredShader;
struct Scene;
class SceneResources;

// The binding with the command's --store and --repeat what-ifs added; a what-if that is not
// line:column or a name throws InputError naming the flag.
ShaderBinding withWhatIfs(const ShaderBinding& binding, const FactorCommandOptions& options);

// Splits measured as the scene has them and, for a what-if, on a copy of the scene whose
// objects (`objects`, indices into scene.objects) carry it as a scene file's "factoring"
// would. The static phases are made when first needed. Borrows every argument: they must
// outlive it.
class SplitMeasures {
  public:
    SplitMeasures(const Scene& scene, const SceneResources& resources,
                  const FactorCommandOptions& options, const std::vector<size_t>& objects);
    ~SplitMeasures();
    SplitMeasures(const SplitMeasures&) = delete;
    SplitMeasures& operator=(const SplitMeasures&) = delete;

    SplitVerification asTheSceneHasIt(size_t object);
    SplitVerification withTheWhatIf(size_t object);
    // The precision "auto" gives object `object`'s map (phases/map_precision.h), checked at
    // frame `frame`'s view as a static run there would check it.
    MapPrecisionCheck precisionAt(size_t object, int frame);

    // The measures of object `object`'s split `f` (--verify, its bakes, and with a what-if
    // `without`, the split without it, measured beside it; null: no what-if), printed to
    // stdout or, when `doc` is set, added to it. Measures nothing unless options.verify or
    // either split has bakes. False when --verify finds the split over options.tolerance.
    bool report(const FactoredShader& f, const FactoredShader* without, size_t object,
                nlohmann::json* doc);

  private:
    const Scene& scene_;
    const SceneResources& resources_;
    const FactorCommandOptions& options_;
    const std::vector<size_t>& objects_;
    StaticPhaseOptions staticOptions_;
    std::unique_ptr<StaticPhase> statics_;
    std::unique_ptr<Scene> whatIfScene_;
    std::unique_ptr<SceneResources> whatIfResources_;
    std::unique_ptr<StaticPhase> whatIfStatics_;
};

}  // namespace mpshade
