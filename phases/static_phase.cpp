#include "phases/static_phase.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>

#include "phases/fixed_point_warp.h"
#include "phases/map_precision.h"
#include "phases/stored_representation.h"
#include "scene/scene_state.h"
#include "scene/variability.h"
#include "shadermaps/tile_store.h"
#include "shading/builtins.h"
#include "shading/program_digest.h"
#include "shading/shading_batch.h"

namespace mpshade {
namespace {

using Clock = std::chrono::steady_clock;

// The shading-input rows of a geometric global, in VertexAttributes' order; -1 for those
// the facet itself supplies (P, from where the sample's ray meets it; I, from P and the eye).
int rowOf(GlobalId id) {
    switch (id) {
        case GlobalId::N:
            return VertexAttributes::Nx;
        case GlobalId::Ng:
            return VertexAttributes::Ngx;
        case GlobalId::dPdu:
            return VertexAttributes::dPdux;
        case GlobalId::dPdv:
            return VertexAttributes::dPdvx;
        case GlobalId::u:
            return VertexAttributes::U;
        case GlobalId::v:
            return VertexAttributes::V;
        case GlobalId::s:
            return VertexAttributes::S;
        case GlobalId::t:
            return VertexAttributes::T;
        default:
            return -1;
    }
}

bool isOpaque(const IrProgram& dynamicPart) {
    for (int v : dynamicPart.oi) {
        const Inst* def = nullptr;
        for (const Inst& inst : dynamicPart.insts)
            if (inst.result <= v && v < inst.result + inst.nout) def = &inst;
        if (!def || def->op != Op::Const || def->constant != 1.0f) return false;
    }
    return true;
}

bool readsFrame(const IrProgram& program, const ShaderBinding& binding) {
    for (const Inst& inst : program.insts) {
        switch (inst.op) {
            case Op::Global: {
                const auto id = static_cast<GlobalId>(inst.imm);
                if (id == GlobalId::I || id == GlobalId::E || id == GlobalId::time) return true;
                break;
            }
            case Op::Param:
            case Op::LightAmbient:
                return true;
            case Op::Diffuse:
            case Op::Specular:
            case Op::Phong: {
                const size_t light = static_cast<size_t>(inst.imm);
                if (light < binding.lights.size() && binding.lights[light].movesRelativeToObject)
                    return true;
                break;
            }
            default:
                break;
        }
    }
    return false;
}

// Occlusion rays leave from the shading point: from a facet at the geometric tolerance, up
// to a quarter pixel inside the exact surface they are traced against, they would hit it.
bool castsRays(const IrProgram& program) {
    for (const Inst& inst : program.insts)
        if (inst.op == Op::Occlusion) return true;
    return false;
}

// The VertexAttributes rows a program reads, in the order it first reads them.
std::vector<int> geometryRowsOf(const IrProgram& program) {
    std::vector<int> rows;
    for (const Inst& inst : program.insts) {
        if (inst.op != Op::Global) continue;
        const int row = rowOf(static_cast<GlobalId>(inst.imm));
        if (row < 0) continue;
        for (int k = 0; k < inst.nout; ++k)
            if (std::find(rows.begin(), rows.end(), row + k) == rows.end()) rows.push_back(row + k);
    }
    return rows;
}

// Per-thread scratch for the static shading of vertices.
struct VertexScratch {
    ShadingBatch batch;
    std::vector<float> workspace;
};

constexpr size_t kChunk = 1024;

}  // namespace

StaticPhase::StaticPhase(const Scene& scene, const SceneResources& resources,
                         const StaticPhaseOptions& options)
    : scene_(scene), resources_(resources), options_(options) {
    for (const SceneObject& obj : scene.objects) {
        auto s = std::make_unique<ObjectShading>();
        const ShaderBinding binding = bindingOf(scene, obj);
        s->factored = forObject(scene, obj,
                                [&] { return factorShader(*obj.shader, binding, options.factor); });
        s->staticKernel = std::make_unique<ShaderKernel>(s->factored.staticPart);
        s->dynamicKernel = std::make_shared<const ShaderKernel>(s->factored.dynamicPart);
        s->opaque = isOpaque(s->factored.dynamicPart);
        s->closed = isClosed(*obj.surface);
        s->staticReadsFrame = readsFrame(s->factored.staticPart, binding);
        s->geometryRows = geometryRowsOf(s->factored.dynamicPart);
        s->directKernel = resources.object(objects_.size()).kernel;
        s->directRows = geometryRowsOf(s->directKernel->program());
        s->directOpaque = isOpaque(s->directKernel->program());
        s->directAllowed = !castsRays(s->directKernel->program());
        objects_.push_back(std::move(s));
    }
    checks_.resize(objects_.size());
}

StaticPhase::~StaticPhase() = default;

DicingView StaticPhase::dicingView(const ObjectState& state, const CameraState& camera) {
    DicingView view;
    view.eye = state.eye;
    view.pixelsPerUnit = 0.5f * static_cast<float>(camera.height) / camera.tanHalfFovY;
    // A length at angle a off the view axis projects up to 1 / cos^2 a = 1 + tan^2 a
    // times longer than on the axis; a is at most the frustum's half diagonal.
    const float tx = camera.tanHalfFovY * camera.aspect, ty = camera.tanHalfFovY;
    view.fovSlack = 1.0f + tx * tx + ty * ty;
    view.nearDistance = camera.zNear / state.scale;
    view.forward = viewForward(state, camera);
    view.halfDiagonalFov = std::atan(std::sqrt(tx * tx + ty * ty));
    view.projects = true;
    objectToScreen(state.objectToWorld, camera, view.screen);
    view.nearW = camera.zNear;
    return view;
}

double StaticPhase::combinedFacets(size_t object, const ObjectState& state,
                                   const CameraState& camera) const {
    DicingOptions survey = options_.combinedDicing;
    survey.surveyOnly = true;
    const SceneObject& sceneObject = scene_.objects[object];
    // The survey dices too (the courtyard's 50 objects: 50 ms of a warm run's first frame),
    // so its estimate is kept in the store like the facets.
    Digest128 key;
    if (stores(object)) {
        ContentHasher h;
        h.addString("mpshade facet survey");
        addDicingInputs(h, object, survey, state, camera);
        key = h.finish();
        std::vector<unsigned char> record;
        double estimate = 0.0;
        if (options_.store->readRecord(key, record) && record.size() == sizeof estimate) {
            std::memcpy(&estimate, record.data(), sizeof estimate);
            if (std::isfinite(estimate) && estimate >= 0.0) return estimate;
        }
    }
    const double estimate =
        diceSurface(*sceneObject.surface, dicingView(state, camera), sceneObject.range, survey)
            .estimatedFacets;
    if (key != Digest128{})
        options_.store->writeRecord(
            key, {reinterpret_cast<const unsigned char*>(&estimate), sizeof estimate});
    return estimate;
}

namespace {

// Whether a representation read from the store has every vertex row its dynamic part reads
// and, for combined facets, the n-tuple's `channels` rows: a record is not trusted.
bool holdsRows(const ObjectRepresentation& rep, bool combined, size_t channels) {
    const VertexAttributes& a = rep.mesh.attributes;
    if (combined && static_cast<size_t>(rep.mesh.channels) != channels) return false;
    if (!combined && rep.mesh.channels != 0) return false;
    for (int row : rep.geometryRows)
        if (row < 0 || static_cast<size_t>(row) >= a.rows.size() ||
            a.rows[static_cast<size_t>(row)].size() != a.count)
            return false;
    for (size_t c = 0; c < static_cast<size_t>(rep.mesh.channels); ++c)
        if (a.rows[VertexAttributes::kGeometryRows + c].size() != a.count) return false;
    return true;
}

// A channel's name in a stored map's description: its variable and component ("Cd[1]"),
// or, for a temporary, its operation, source position and component ("mul@14:33[0]").
std::string channelName(const ChannelInfo& c) {
    if (!c.name.empty()) return c.name;
    std::string name =
        std::string(opName(c.op)) + "@" + std::to_string(c.line) + ":" + std::to_string(c.column);
    if (c.component >= 0) name += "[" + std::to_string(c.component) + "]";
    return name;
}

// The diced surface's positions, facets and chart points moved into `mesh` (the facets'
// position indices through the welded positions).
void takeDicedMesh(DicedSurface& diced, FacetMesh& mesh) {
    mesh.format = diced.format;
    mesh.qx = std::move(diced.qx);
    mesh.qy = std::move(diced.qy);
    mesh.qz = std::move(diced.qz);
    mesh.positionIndex.resize(diced.triangles.size());
    for (size_t k = 0; k < diced.triangles.size(); ++k)
        mesh.positionIndex[k] = diced.positionOf[diced.triangles[k]];
    mesh.attributeIndex = std::move(diced.triangles);
    std::vector<uint32_t>().swap(diced.positionOf);
    mesh.attributeChartPoint = std::move(diced.attributePoints);
    mesh.clusters = std::move(diced.clusters);
}

// The longest projected edge the facets have at the representative view, pixels, measured
// as the dynamic phase measures it (through the fixed-point warp).
float longestEdgePixels(const FacetMesh& mesh, const ObjectState& state,
                        const CameraState& camera) {
    const FixedPointWarp warp(state.objectToWorld, camera, mesh.format);
    WarpedVertices warped;
    warp.warp(mesh.qx.data(), mesh.qy.data(), mesh.qz.data(), mesh.positionCount(), warped);
    int64_t longest = 0;
    for (size_t f = 0; f < mesh.facetCount(); ++f) {
        const uint32_t* p = &mesh.positionIndex[3 * f];
        if (warped.culled(p[0]) || warped.culled(p[1]) || warped.culled(p[2])) continue;
        for (int i = 0; i < 3; ++i) {
            const int64_t dx = warped.x[p[(i + 1) % 3]] - warped.x[p[i]];
            const int64_t dy = warped.y[p[(i + 1) % 3]] - warped.y[p[i]];
            longest = std::max(longest, dx * dx + dy * dy);
        }
    }
    return static_cast<float>(std::sqrt(static_cast<double>(longest))) / 256.0f;
}

// The vertex attributes: the geometry rows the dynamic kernel reads, and with `runStatic` (a
// combined representation) the n-tuple of mesh.channels the static part computes at each
// vertex. Returns the static shader instructions run.
uint64_t shadeVertices(const ObjectShading& obj, const std::vector<int>& geometryRows,
                       const DicedSurface& diced, const ObjectState& state,
                       const ShadingUniforms& uniforms, bool runStatic, FacetMesh& mesh) {
    const size_t staticChannels = static_cast<size_t>(mesh.channels);
    const size_t n = mesh.attributeChartPoint.size();
    VertexAttributes& attr = mesh.attributes;
    attr.count = n;
    attr.rows.assign(VertexAttributes::kGeometryRows + staticChannels, {});
    for (int row : geometryRows) attr.rows[static_cast<size_t>(row)].resize(n);
    for (size_t c = 0; c < staticChannels; ++c)
        attr.rows[VertexAttributes::kGeometryRows + c].resize(n);
    tbb::enumerable_thread_specific<VertexScratch> scratch;
    std::atomic<uint64_t> instructions{0};
    tbb::parallel_for(size_t{0}, (n + kChunk - 1) / kChunk, [&](size_t chunk) {
        enableFlushToZero();
        VertexScratch& b = scratch.local();
        const size_t begin = chunk * kChunk, m = std::min(kChunk, n - begin);
        b.batch.resize(m, staticChannels);
        for (size_t i = 0; i < m; ++i) {
            const SurfaceSample& g = diced.attributeGeometry[begin + i];
            const ChartPoint& at = mesh.attributeChartPoint[begin + i];
            const glm::vec3 I = glm::normalize(g.P - state.eye);
            b.batch.setPoint(i, g, at, I);
            for (int row : geometryRows) {
                // VertexAttributes rows follow the shading batch's first 15 rows, then
                // u v s t (the batch's rows U..T, after I).
                const int src = row < VertexAttributes::U ? row : row + 3;
                attr.rows[static_cast<size_t>(row)][begin + i] = b.batch.row(src)[i];
            }
        }
        if (!runStatic) return;
        ShadingCounters counters;
        obj.staticKernel->run(uniforms, b.batch.in, m, b.batch.out, b.workspace, counters);
        instructions += counters.instructions;
        for (size_t c = 0; c < staticChannels; ++c)
            std::copy(b.batch.out.channels[c], b.batch.out.channels[c] + m,
                      attr.rows[VertexAttributes::kGeometryRows + c].begin() + begin);
    });
    return instructions;
}

}  // namespace

// Dices the surface for the view's range, moves the facets into the representation, and
// shades its vertices; a combined representation also measures its longest edge, a
// separate one gets a shader map (the previous one, still valid, or a new one with its
// always-resident levels), a direct one the whole shader as its dynamic kernel.
std::unique_ptr<ObjectRepresentation> StaticPhase::build(size_t index, Representation kind,
                                                         const ObjectState& state,
                                                         const CameraState& camera,
                                                         const ShadingUniforms& uniforms,
                                                         const ObjectRepresentation* previous,
                                                         StaticCosts& costs) const {
    const auto start = Clock::now();
    const ObjectShading& obj = *objects_[index];
    const SceneObject& sceneObject = scene_.objects[index];
    const Surface& surface = *sceneObject.surface;
    const bool direct = kind == Representation::Direct;
    const bool useMap = kind == Representation::ShaderMap;
    const bool combined = !useMap && !direct;
    const DicingView view = dicingView(state, camera);
    const DicingOptions dicing = dicingFor(index, combined, direct);

    auto rep = std::make_unique<ObjectRepresentation>();
    rep->kind = combined ? Representation::Facets : kind;
    rep->representativeEye = state.eye;
    rep->representativeForward = view.forward;
    rep->center = surfaceBounds(surface).center();
    rep->range = sceneObject.range;
    rep->frustumCulled = dicing.frustumCull;
    rep->imageHeight = camera.height;
    rep->maxEdgePixels = 0.0f;
    rep->dynamicKernel = direct ? obj.directKernel : obj.dynamicKernel;
    rep->geometryRows = direct ? obj.directRows : obj.geometryRows;
    rep->opaque = direct ? obj.directOpaque : obj.opaque;
    rep->closed = obj.closed;
    const size_t channels = obj.factored.staticPart.channelOutputs.size();
    // The facets: read from the store where an earlier run built the same ones (the
    // same geometry, view, state, options and, for combined facets, static program and
    // inputs), else diced and shaded here (and stored).
    const Digest128 key = stores(index)
                              ? representationKey(index, combined, direct, state, camera, uniforms)
                              : Digest128{};
    std::vector<unsigned char> record;
    if (key != Digest128{} && options_.store->readRecord(key, record) &&
        unpackRepresentation(record, *rep) && holdsRows(*rep, combined, channels)) {
        ++costs.representationsLoaded;
    } else {
        DicedSurface diced = diceSurface(surface, view, sceneObject.range, dicing);
        rep->charts = diced.charts;
        rep->patches = diced.patches;
        rep->culledPatches = diced.culledCharts;
        rep->frustumCulledPatches = diced.frustumCulled;
        rep->cappedPatches = diced.cappedCharts;
        FacetMesh& mesh = rep->mesh;
        takeDicedMesh(diced, mesh);
        mesh.channels = combined ? static_cast<int>(channels) : 0;
        // The survey between grid points can miss a little, so the facets are diced again
        // when their edges outgrow P/2 or, if dicing overshot it, what they started at.
        if (combined)
            rep->maxEdgePixels =
                std::max(dicing.maxEdgePixels, 1.05f * longestEdgePixels(mesh, state, camera));
        costs.instructions +=
            shadeVertices(obj, rep->geometryRows, diced, state, uniforms, combined, mesh);
        if (combined) costs.programRuns += mesh.attributeChartPoint.size();
        if (key != Digest128{}) options_.store->writeRecord(key, packRepresentation(*rep));
    }
    if (direct || combined) {
        // Nothing more: the dynamic phase runs the whole shader, or the facets hold the
        // n-tuple.
    } else if (channels == 0) {
        // Nothing static is stored (factoring.h, storeAboveCost): no map to make.
    } else if (previous && previous->map && !obj.staticReadsFrame) {
        rep->map = previous->map;  // still valid: its tiles are kept
    } else {
        const auto mapStart = Clock::now();
        rep->map = makeShaderMap(index, uniforms);
        costs.addFill(rep->map->fillStats(), obj.staticKernel->instructionCount());
        // A map the next run keeps (the branch above): its making is not that run's price.
        if (!obj.staticReadsFrame)
            costs.keptMapSeconds += std::chrono::duration<double>(Clock::now() - mapStart).count();
    }
    ++costs.runs;
    costs.seconds += std::chrono::duration<double>(Clock::now() - start).count();
    return rep;
}

bool StaticPhase::buildMakesMap(size_t index, Representation kind,
                                const ObjectRepresentation* previous) const {
    const ObjectShading& obj = *objects_[index];
    return kind == Representation::ShaderMap && !obj.factored.staticPart.channelOutputs.empty() &&
           !(previous && previous->map && !obj.staticReadsFrame);
}

// Whether object `index`'s static work is kept in the store: there is one, and the
// geometry has a digest (objects made in code, not loaded, have none).
bool StaticPhase::stores(size_t index) const {
    return options_.store && scene_.objects[index].geometryDigest != Digest128{};
}

// What dicing object `index` for this frame depends on: the engine, the geometry, the
// object's state and the camera at the frame (so its dicing view), the options and range.
DicingOptions StaticPhase::dicingFor(size_t index, bool combined, bool direct) const {
    if (combined) return options_.combinedDicing;
    DicingOptions d = options_.separateDicing;
    const ObjectShading& obj = *objects_[index];
    const bool mapped = !direct && !obj.factored.staticPart.channelOutputs.empty();
    const std::vector<int>& rows = direct ? obj.directRows : obj.geometryRows;
    const bool readsChart = std::any_of(rows.begin(), rows.end(), [](int row) {
        return row >= VertexAttributes::dPdux && row < VertexAttributes::kGeometryRows;
    });
    d.chartExact = d.chartExact && (mapped || readsChart);
    return d;
}

void StaticPhase::addDicingInputs(ContentHasher& h, size_t index, const DicingOptions& d,
                                  const ObjectState& state, const CameraState& camera) const {
    const SceneObject& object = scene_.objects[index];
    h.addU64(kEvaluationVersion).addDigest(engineDigest()).addDigest(object.geometryDigest);
    h.addBytes(&state.objectToWorld, sizeof state.objectToWorld)
        .addBytes(&state.worldToObject, sizeof state.worldToObject)
        .addFloat(state.scale)
        .addBytes(&state.eye, sizeof state.eye);
    for (const glm::vec3& v : {camera.eye, camera.forward, camera.right, camera.up})
        h.addBytes(&v, sizeof v);
    h.addFloat(camera.tanHalfFovY).addFloat(camera.aspect).addFloat(camera.zNear);
    h.addFloat(camera.zFar).addI32(camera.width).addI32(camera.height);
    h.addI32(static_cast<int32_t>(d.target)).addFloat(d.maxEdgePixels).addFloat(d.flatnessPixels);
    h.addI32(d.overRange).addI32(d.maxEdgeRate).addI32(d.maxSplitDepth).addI32(d.maxPatches);
    h.addU64(d.maxFacets).addI32(d.frustumCull).addI32(d.surveyOnly).addI32(d.chartExact);
    h.addFloat(object.range.distanceFactor).addFloat(object.range.angle);
}

// Everything a representation's facets depend on: the dicing's inputs, the kind, the
// vertex rows kept, and for combined facets the static program and the uniforms it reads.
Digest128 StaticPhase::representationKey(size_t index, bool combined, bool direct,
                                         const ObjectState& state, const CameraState& camera,
                                         const ShadingUniforms& uniforms) const {
    const ObjectShading& obj = *objects_[index];
    ContentHasher h;
    h.addString("mpshade representation");
    addDicingInputs(h, index, dicingFor(index, combined, direct), state, camera);
    h.addI32(combined).addI32(direct);
    const std::vector<int>& rows = direct ? obj.directRows : obj.geometryRows;
    h.addU64(rows.size()).addBytes(rows.data(), rows.size() * sizeof(int));
    if (combined) {
        addProgram(h, obj.staticKernel->program());
        addUniformsRead(h, obj.staticKernel->program(), uniforms);
    }
    return h.finish();
}

ShaderMapOptions StaticPhase::mapOptions(size_t object) const {
    const SceneObject& sceneObject = scene_.objects[object];
    ShaderMapOptions map = options_.shaderMap;
    const int cap =
        sceneObject.shadermapResolution > 0 ? sceneObject.shadermapResolution : map.resolution;
    int resolution = 1;
    while (resolution < cap && resolution < (1 << 20)) resolution *= 2;
    map.resolution = resolution;
    map.tileSize = std::min(map.tileSize, resolution);
    map.halfPrecision = map.halfPrecision || sceneObject.shadermapPrecision == MapPrecision::Half;
    return map;
}

// A new map with the object's options (mapOptions), its tiles in the pool for its tile size.
std::shared_ptr<ShaderMap> StaticPhase::makeShaderMap(size_t index,
                                                      const ShadingUniforms& uniforms) const {
    const ObjectShading& obj = *objects_[index];
    const SceneObject& sceneObject = scene_.objects[index];
    const size_t channels = obj.factored.staticPart.channelOutputs.size();
    ShaderMapOptions mapOptions = this->mapOptions(index);
    mapOptions.halfPrecision = mapOptions.halfPrecision || measuredHalf(index, uniforms);
    return std::make_shared<ShaderMap>(
        *sceneObject.surface, *obj.staticKernel, uniforms, mapOptions,
        pools_.forTileBytes(ShaderMap::tileBytesFor(mapOptions, static_cast<int>(channels))),
        storedTiles(index, uniforms, mapOptions));
}

bool StaticPhase::measuredHalf(size_t index, const ShadingUniforms& uniforms) const {
    const SceneObject& sceneObject = scene_.objects[index];
    const ObjectShading& obj = *objects_[index];
    if (!options_.measurePrecision || sceneObject.shadermapPrecision != MapPrecision::Auto ||
        obj.factored.staticPart.channelOutputs.empty())
        return false;
    // What the check depends on: both parts and the uniforms they read, the surface, the
    // check's own options.
    ContentHasher h;
    h.addString("mpshade map precision").addDigest(engineDigest());
    addProgram(h, obj.staticKernel->program());
    addUniformsRead(h, obj.staticKernel->program(), uniforms);
    addProgram(h, obj.dynamicKernel->program());
    addUniformsRead(h, obj.dynamicKernel->program(), uniforms);
    h.addDigest(sceneObject.geometryDigest)
        .addI32(options_.precision.points)
        .addBytes(&options_.precision.tolerance, sizeof(double))
        .addBytes(&options_.precision.maxValue, sizeof(double));
    TileStore* store = stores(index) ? options_.store.get() : nullptr;
    const MapPrecisionCheck check = checkHalfPrecisionKept(
        *this, *sceneObject.surface, index, uniforms, options_.precision, store, h.finish());
    std::lock_guard<std::mutex> lock(checksMutex_);
    checks_[index] = check;
    return check.half;
}

std::optional<MapPrecisionCheck> StaticPhase::precisionCheck(size_t object) const {
    std::lock_guard<std::mutex> lock(checksMutex_);
    return checks_[object];
}

// Everything a tile's texels depend on (tile_store.h): the static program and the uniform
// values it reads, the surface, and the map's layout.
StoredTiles StaticPhase::storedTiles(size_t index, const ShadingUniforms& uniforms,
                                     const ShaderMapOptions& map) const {
    const SceneObject& sceneObject = scene_.objects[index];
    if (!stores(index)) return {};
    const IrProgram& program = objects_[index]->staticKernel->program();
    ContentHasher hasher;
    hasher.addString("mpshade shader map").addDigest(engineDigest());
    addProgram(hasher, program);
    addUniformsRead(hasher, program, uniforms);
    hasher.addDigest(sceneObject.geometryDigest)
        .addI32(map.resolution)
        .addI32(map.tileSize)
        .addI32(map.border)
        .addI32(map.halfPrecision)
        .addI32(static_cast<int32_t>(map.prefilter))
        .addI32(map.supersampleLimit)
        .addI32(map.seamless)
        .addI32(map.chartAspect);
    StoredTiles stored{options_.store, hasher.finish()};
    StoredMapInfo info;
    info.object = sceneObject.name;
    info.shader = sceneObject.shaderName;
    for (const ChannelInfo& c : objects_[index]->factored.channels)
        info.channelNames.push_back(channelName(c));
    info.charts = chartCount(*sceneObject.surface);
    info.resolution = map.resolution;
    info.tileSize = map.tileSize;
    info.border = map.border;
    info.halfPrecision = map.halfPrecision;
    info.engine = engineDigest().hex();
    options_.store->useMap(stored.digest, info);
    return stored;
}

void StaticPhase::fill(std::span<const TileRequest> requests,
                       std::span<const ObjectRepresentation* const> representations,
                       StaticCosts& costs, FillTiming* timing, const StopSignal* stop) const {
    if (timing) {
        timing->objectSeconds.resize(objects_.size(), 0.0);
        timing->objectInstructions.resize(objects_.size(), 0);
        timing->objectTilesLoaded.resize(objects_.size(), 0);
    }
    if (requests.empty()) return;
    const auto start = Clock::now();
    std::map<uint32_t, std::vector<TileKey>> perObject;
    for (const TileRequest& r : requests) perObject[r.object].push_back(r.key);
    struct Work {
        ShaderMap* map;
        std::vector<TileKey>* keys;
        size_t instructionsPerRun;
        uint32_t object;
        double seconds = 0.0;
    };
    std::vector<Work> work;
    for (auto& [object, keys] : perObject) {
        const ObjectRepresentation* rep = representations[object];
        if (rep && rep->map)
            work.push_back({rep->map.get(), &keys,
                            objects_[object]->staticKernel->instructionCount(), object});
    }
    // What each fill did, as it reports it: another thread may be filling the same map.
    std::vector<FillStats> done(work.size());
    tbb::parallel_for(size_t{0}, work.size(), [&](size_t w) {
        const auto began = Clock::now();
        done[w] = work[w].map->fill(*work[w].keys, stop);
        const auto ended = Clock::now();
        work[w].seconds = std::chrono::duration<double>(ended - began).count();
        if (timing && timing->trace)
            timing->trace->span("fill tiles", PhaseKind::Static, SpanLevel::Task, began, ended,
                                work[w].object, timing->frame);
    });
    if (timing)
        for (const Work& w : work) timing->objectSeconds[w.object] += w.seconds;
    for (size_t w = 0; w < work.size(); ++w) {
        costs.addFill(done[w], work[w].instructionsPerRun);
        if (timing) {
            timing->objectInstructions[work[w].object] +=
                done[w].programRuns * work[w].instructionsPerRun;
            timing->objectTilesLoaded[work[w].object] += done[w].tilesLoaded;
        }
    }
    costs.seconds += std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace mpshade
