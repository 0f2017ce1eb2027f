// static_phase.h -- the patent's static phase (FIG. 2, 220): per object, rarely, the
// static TSI (dicing, dicing.h) and the static shader S_s, stored as the object's
// intermediate representation (object_representation.h); and, on demand, the shader-map
// tiles frames ask for.
//
// What is fixed for the whole render is worked out once per object (ObjectShading): its
// shader factored for its binding, both parts compiled, and what the dynamic part reads.
#pragma once

#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <vector>

#include "phases/dicing.h"
#include "phases/map_precision.h"
#include "phases/object_representation.h"
#include "phases/phase_trace.h"
#include "phases/scene_resources.h"
#include "shading/factoring.h"
#include "shading/stop_signal.h"

namespace mpshade {

struct StaticPhaseOptions {
    FactorOptions factor;
    // The combined representation: edges under P/2 at the representative view.
    DicingOptions combinedDicing = {DicingTarget::EdgeLength, 0.5f, 0.25f, false};
    // The separate representation: within 1/4 pixel of the surface over the range.
    DicingOptions separateDicing = {DicingTarget::Flatness, 0.5f, 0.25f, true};
    ShaderMapOptions shaderMap;  // resolution: capped per object by the scene
    // Objects whose "shadermap_precision" is auto: binary16 where measured not to show
    // (map_precision.h); false: float.
    bool measurePrecision = true;
    MapPrecisionOptions precision;
    // Where shader-map tiles are kept between runs (shadermaps/tile_store.h); null: nowhere,
    // every tile is filled by the static shader.
    std::shared_ptr<TileStore> store;
};

// One object's shading, as both phases need it, fixed for the whole render.
struct ObjectShading {
    FactoredShader factored;
    std::unique_ptr<ShaderKernel> staticKernel;
    std::shared_ptr<const ShaderKernel> dynamicKernel;
    // VertexAttributes rows the dynamic part reads (P and I come from the facet itself).
    std::vector<int> geometryRows;
    // A direct representation's dynamic kernel: the whole shader as the reference runs it
    // (shared with SceneResources), the rows it reads, whether its Oi is 1, and whether it
    // may run on facets at all (not if it traces occlusion rays from the shading point).
    std::shared_ptr<const ShaderKernel> directKernel;
    std::vector<int> directRows;
    bool directOpaque = true;
    bool directAllowed = true;
    bool opaque = true;   // the dynamic part's Oi is the constant 1
    bool closed = false;  // the surface bounds a solid
    // The static part reads the view, the time or an animated input (through bake()): its
    // values hold for the representative view only, so a new static run needs new ones.
    bool staticReadsFrame = false;
};

// What static work cost (accumulated).
struct StaticCosts {
    int runs = 0;  // representations built
    double seconds = 0.0;
    // Of `seconds`: making new shader maps (their always-resident levels filled) that the
    // object's later runs keep, so do not pay again (not those whose static part reads the
    // frame: each run makes its map anew).
    double keptMapSeconds = 0.0;
    uint64_t instructions = 0;  // static shader instructions, times lanes
    uint64_t tilesFilled = 0, tilesFromChildren = 0, texelsFilled = 0, programRuns = 0;
    uint64_t tilesLoaded = 0;       // read from the store instead of filled
    int representationsLoaded = 0;  // of runs: facets read from the store, not diced

    // A map's fill, whose static program costs `instructionsPerRun` per evaluation.
    void addFill(const FillStats& f, uint64_t instructionsPerRun) {
        tilesFilled += f.tiles;
        tilesLoaded += f.tilesLoaded;
        tilesFromChildren += f.tilesFromChildren;
        texelsFilled += f.texels;
        programRuns += f.programRuns;
        instructions += f.programRuns * instructionsPerRun;
    }
    StaticCosts& operator+=(const StaticCosts& o) {
        runs += o.runs;
        seconds += o.seconds;
        keptMapSeconds += o.keptMapSeconds;
        instructions += o.instructions;
        tilesFilled += o.tilesFilled;
        tilesLoaded += o.tilesLoaded;
        representationsLoaded += o.representationsLoaded;
        tilesFromChildren += o.tilesFromChildren;
        texelsFilled += o.texelsFilled;
        programRuns += o.programRuns;
        return *this;
    }
};

// Where a fill's work went: each map's fill reported as a span on the thread that ran it,
// and added to its object's seconds and static shader instructions (both sized to the
// scene's objects by fill()).
struct FillTiming {
    PhaseTrace* trace = nullptr;  // not owned; null: no spans
    int64_t frame = -1;
    std::vector<double> objectSeconds;
    std::vector<uint64_t> objectInstructions;
    std::vector<uint64_t> objectTilesLoaded;  // tiles read from the store
};

class StaticPhase {
  public:
    StaticPhase(const Scene& scene, const SceneResources& resources,
                const StaticPhaseOptions& options = {});
    ~StaticPhase();

    const ObjectShading& shading(size_t object) const { return *objects_[object]; }
    // Where every map this static phase makes keeps its tiles.
    TilePools& tilePools() const { return pools_; }
    const StaticPhaseOptions& options() const { return options_; }
    // The options object `object`'s shader map is made with: the options' but for its
    // resolution (the object's cap, else the options', rounded up to a power of two), a
    // tile no larger than that, and half precision where the object asks for it (an object
    // whose precision is auto is measured when its map is made: float here).
    ShaderMapOptions mapOptions(size_t object) const;

    // Object `object`'s representation for the view of `camera` (its representative view).
    // `previous` (may be null) lends its shader map when the static part does not read the
    // frame. Safe to call for different objects in parallel.
    std::unique_ptr<ObjectRepresentation> build(size_t object, Representation kind,
                                                const ObjectState& state, const CameraState& camera,
                                                const ShadingUniforms& uniforms,
                                                const ObjectRepresentation* previous,
                                                StaticCosts& costs) const;

    // Whether build() would make a new shader map (and so fill tiles of its always-resident
    // levels) rather than lend `previous`'s or need none.
    bool buildMakesMap(size_t object, Representation kind,
                       const ObjectRepresentation* previous) const;

    // The facets the combined representation of object `object` would have at this view
    // (the dicing survey's estimate, before any budget): for choosing a representation.
    double combinedFacets(size_t object, const ObjectState& state, const CameraState& camera) const;

    // Fills the requested tiles missing from the representations' maps: each map's tiles
    // in one batch (finest level first), maps in parallel. `stop` (may be null): as
    // ShaderMap::fill's; a map's pass under way when it says stop is dropped.
    void fill(std::span<const TileRequest> requests,
              std::span<const ObjectRepresentation* const> representations, StaticCosts& costs,
              FillTiming* timing = nullptr, const StopSignal* stop = nullptr) const;

    // The last precision check of object `object`'s map (map_precision.h); none if none ran
    // (its precision not auto, or no map made).
    std::optional<MapPrecisionCheck> precisionCheck(size_t object) const;

  private:
    static DicingView dicingView(const ObjectState& state, const CameraState& camera);
    std::shared_ptr<ShaderMap> makeShaderMap(size_t index, const ShadingUniforms& uniforms) const;
    StoredTiles storedTiles(size_t index, const ShadingUniforms& uniforms,
                            const ShaderMapOptions& map) const;
    bool stores(size_t index) const;
    // For a map made with `uniforms`: binary16 if the object's precision is auto and the check
    // finds it does not show; the check's verdict is kept in the store, if any, so a run whose
    // tiles all come from it does not run the static part to decide.
    bool measuredHalf(size_t index, const ShadingUniforms& uniforms) const;
    // The dicing of an object's combined facets, or of its separate or direct ones: chart
    // coordinates kept exact (DicingOptions::chartExact) unless nothing reads them -- no
    // map, and a dynamic part that reads no u, v, s, t, dPdu or dPdv.
    DicingOptions dicingFor(size_t index, bool combined, bool direct) const;
    void addDicingInputs(ContentHasher& h, size_t index, const DicingOptions& dicing,
                         const ObjectState& state, const CameraState& camera) const;
    Digest128 representationKey(size_t index, bool combined, bool direct, const ObjectState& state,
                                const CameraState& camera, const ShadingUniforms& uniforms) const;

    const Scene& scene_;
    const SceneResources& resources_;
    StaticPhaseOptions options_;
    std::vector<std::unique_ptr<ObjectShading>> objects_;
    mutable TilePools pools_;
    mutable std::mutex checksMutex_;
    mutable std::vector<std::optional<MapPrecisionCheck>> checks_;  // per object, the last
};

}  // namespace mpshade
