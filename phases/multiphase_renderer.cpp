#include "phases/multiphase_renderer.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>

#include "scene/variability.h"
#include "shading/shading_batch.h"

namespace mpshade {
namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

// The shading-input rows of a geometric global, in VertexAttributes' order.
int rowOf(GlobalId id) {
    switch (id) {
        case GlobalId::P:
            return VertexAttributes::Px;
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

// Per-thread scratch for one chunk of points: the shading batch, probe queries and results.
struct ChunkBuffers {
    ShadingBatch batch;
    std::vector<ProbeQuery> queries;
    std::vector<float> probed;
    std::vector<float> workspace;

    void prepare(size_t n, size_t channels) {
        batch.resize(n, channels);
        queries.resize(n);
    }
};

constexpr size_t kChunk = 1024;

// Per cluster: whether any of it can be seen this frame. Off screen: its bounding sphere is
// wholly outside a side plane or in front of the near plane. Facing away: every normal of
// its cone points away from the eye for every point of its sphere (normal-cone culling).
std::vector<uint8_t> clusterVisibility(const FacetMesh& mesh, const ObjectState& state,
                                       const CameraState& camera, bool backFaces) {
    const float tx = camera.tanHalfFovY * camera.aspect, ty = camera.tanHalfFovY;
    const glm::vec3 planes[4] = {glm::normalize(camera.right - tx * camera.forward),
                                 glm::normalize(-camera.right - tx * camera.forward),
                                 glm::normalize(camera.up - ty * camera.forward),
                                 glm::normalize(-camera.up - ty * camera.forward)};
    std::vector<uint8_t> visible(mesh.clusters.size(), 1);
    for (size_t k = 0; k < mesh.clusters.size(); ++k) {
        const FacetCluster& c = mesh.clusters[k];
        const glm::vec3 d = glm::vec3(state.objectToWorld * glm::vec4(c.center, 1.0f)) - camera.eye;
        const float r = c.radius * state.scale;
        bool out = glm::dot(d, camera.forward) < camera.zNear - r;
        for (const glm::vec3& n : planes) out = out || glm::dot(d, n) > r;
        if (!out && backFaces && c.coneHalfAngle < 1.5f) {
            const glm::vec3 toCluster = c.center - state.eye;  // object space
            const float distance = glm::length(toCluster);
            if (distance > c.radius) {
                const float spread =
                    c.coneHalfAngle + std::asin(std::min(1.0f, c.radius / distance));
                out = spread < 1.5707963f &&
                      glm::dot(c.coneAxis, toCluster / distance) > std::sin(spread);
            }
        }
        visible[k] = out ? 0 : 1;
    }
    return visible;
}

}  // namespace

struct MultiphaseRenderer::ObjectData {
    FactoredShader factored;
    std::unique_ptr<ShaderKernel> staticKernel;
    std::shared_ptr<const ShaderKernel> dynamicKernel;  // also in each facet mesh's data block
    std::unique_ptr<FacetMesh> mesh;
    std::vector<int> geometryRows;  // attribute rows the dynamic part reads
    bool opaque = true;
    int diceHeight = 0;  // image height the facets were diced for
    // The separate representation (scene option "representation": "shadermap"): the
    // n-tuple comes from probes of a shader map, not from the facets' vertices.
    bool useMap = false;
    bool closed = false;  // the surface bounds a solid
    std::unique_ptr<ShaderMap> map;
    std::vector<LightSample> mapLights;  // the static phase's uniforms, kept for the map
    std::vector<float> mapParams;
};

MultiphaseRenderer::MultiphaseRenderer(const Scene& scene, const MultiphaseOptions& options)
    : scene_(scene), options_(options), resources_(scene) {
    for (const SceneObject& obj : scene.objects) {
        auto data = std::make_unique<ObjectData>();
        data->factored = forObject(scene, obj, [&] {
            return factorShader(*obj.shader, bindingOf(scene, obj), options.factor);
        });
        data->staticKernel = std::make_unique<ShaderKernel>(data->factored.staticPart);
        data->dynamicKernel = std::make_shared<const ShaderKernel>(data->factored.dynamicPart);
        data->opaque = isOpaque(data->factored.dynamicPart);
        data->useMap = obj.representation == Representation::ShaderMap;
        data->closed = isClosed(*obj.surface);
        for (const Inst& inst : data->factored.dynamicPart.insts) {
            if (inst.op != Op::Global) continue;
            const int row = rowOf(static_cast<GlobalId>(inst.imm));
            if (row < 0) continue;
            for (int k = 0; k < inst.nout; ++k)
                if (std::find(data->geometryRows.begin(), data->geometryRows.end(), row + k) ==
                    data->geometryRows.end())
                    data->geometryRows.push_back(row + k);
        }
        objects_.push_back(std::move(data));
    }
}

MultiphaseRenderer::~MultiphaseRenderer() = default;

const FacetMesh* MultiphaseRenderer::facets(size_t object) const {
    return objects_[object]->mesh.get();
}
const FactoredShader& MultiphaseRenderer::factored(size_t object) const {
    return objects_[object]->factored;
}

void MultiphaseRenderer::staticPhase(size_t index, const ObjectState& state,
                                     const CameraState& camera, const ShadingUniforms& uniforms,
                                     FrameStats& stats) {
    ObjectData& obj = *objects_[index];
    const SceneObject& sceneObject = scene_.objects[index];
    const Surface& surface = *sceneObject.surface;
    DicingView view;
    view.eye = state.eye;
    view.pixelsPerUnit = 0.5f * static_cast<float>(camera.height) / camera.tanHalfFovY;
    // A length at angle a off the view axis projects up to 1 / cos^2 a = 1 + tan^2 a
    // times longer than on the axis; a is at most the frustum's half diagonal.
    const float tx = camera.tanHalfFovY * camera.aspect, ty = camera.tanHalfFovY;
    view.fovSlack = 1.0f + tx * tx + ty * ty;
    view.nearDistance = camera.zNear / state.scale;
    view.forward = glm::normalize(glm::vec3(state.worldToObject * glm::vec4(camera.forward, 0.0f)));
    view.halfDiagonalFov = std::atan(std::sqrt(tx * tx + ty * ty));
    const DicedSurface diced = diceSurface(surface, view, sceneObject.range, options_.dicing);

    auto mesh = std::make_unique<FacetMesh>();
    mesh->format = diced.format;
    mesh->qx = diced.qx;
    mesh->qy = diced.qy;
    mesh->qz = diced.qz;
    mesh->attributeIndex = diced.triangles;
    mesh->positionIndex.resize(diced.triangles.size());
    for (size_t k = 0; k < diced.triangles.size(); ++k)
        mesh->positionIndex[k] = diced.positionOf[diced.triangles[k]];
    mesh->attributeChartPoint = diced.attributePoints;
    mesh->clusters = diced.clusters;
    mesh->representativeEye = state.eye;
    mesh->representativeForward = view.forward;
    mesh->frustumCulled = options_.dicing.frustumCull;
    mesh->center = surfaceBounds(surface).center();
    mesh->range = sceneObject.range;
    mesh->charts = diced.charts;
    mesh->culledCharts = diced.culledCharts;
    mesh->cappedCharts = diced.cappedCharts;
    const size_t channels = obj.factored.staticPart.channelOutputs.size();
    mesh->channels = static_cast<int>(channels);

    // Geometry the dynamic part reads, and the n-tuple from the static part.
    const size_t n = diced.attributePoints.size();
    VertexAttributes& attr = mesh->attributes;
    attr.count = n;
    attr.rows.assign(VertexAttributes::kGeometryRows + channels, {});
    for (int row : obj.geometryRows) attr.rows[static_cast<size_t>(row)].resize(n);
    if (!obj.useMap)
        for (size_t c = 0; c < channels; ++c)
            attr.rows[VertexAttributes::kGeometryRows + c].resize(n);
    tbb::enumerable_thread_specific<ChunkBuffers> buffers;
    std::atomic<uint64_t> instructions{0};
    tbb::parallel_for(size_t{0}, (n + kChunk - 1) / kChunk, [&](size_t chunk) {
        ChunkBuffers& b = buffers.local();
        const size_t begin = chunk * kChunk, m = std::min(kChunk, n - begin);
        b.prepare(m, channels);
        for (size_t i = 0; i < m; ++i) {
            const SurfaceSample& g = diced.attributeGeometry[begin + i];
            const ChartPoint& at = diced.attributePoints[begin + i];
            const glm::vec3 I = glm::normalize(g.P - state.eye);
            b.batch.setPoint(i, g, at, I);
            for (int row : obj.geometryRows) {
                // VertexAttributes rows follow the shading batch's first 15 rows, then
                // u v s t (the batch's rows U..T, after I).
                const int src = row < VertexAttributes::U ? row : row + 3;
                attr.rows[static_cast<size_t>(row)][begin + i] = b.batch.row(src)[i];
            }
        }
        if (obj.useMap) return;  // the n-tuple lives in the shader map
        ShadingCounters counters;
        obj.staticKernel->run(uniforms, b.batch.in, m, b.batch.out, b.workspace, counters);
        instructions += counters.instructions;
        for (size_t c = 0; c < channels; ++c)
            std::copy(b.batch.out.channels[c], b.batch.out.channels[c] + m,
                      attr.rows[VertexAttributes::kGeometryRows + c].begin() + begin);
    });
    if (obj.useMap) {
        // Resolution: the scene's, or about one texel per pixel at the closest view the
        // facets were diced for (their edges are ~maxEdgePixels / sqrt(2) there).
        int resolution = sceneObject.shadermapResolution;
        if (resolution <= 0) {
            const double facetsPerChart =
                static_cast<double>(diced.triangles.size() / 3) /
                std::max(1, diced.patches - diced.culledCharts - diced.frustumCulled);
            const double pixelsPerSide =
                std::sqrt(facetsPerChart / 2.0) * options_.dicing.maxEdgePixels / std::sqrt(2.0) *
                std::sqrt(static_cast<double>(diced.patches) / std::max(1, diced.charts));
            resolution = 8;
            while (resolution < pixelsPerSide && resolution < 1024) resolution *= 2;
        }
        int pow2 = 1;
        while (pow2 < resolution) pow2 *= 2;
        obj.mapLights.assign(uniforms.lights.begin(), uniforms.lights.end());
        obj.mapParams.assign(uniforms.params.begin(), uniforms.params.end());
        ShadingUniforms mapUniforms = uniforms;
        mapUniforms.lights = obj.mapLights;
        mapUniforms.params = obj.mapParams;
        ShaderMapOptions mapOptions = options_.shaderMap;
        mapOptions.resolution = pow2;
        obj.map = std::make_unique<ShaderMap>(surface, *obj.staticKernel, mapUniforms, mapOptions);
        obj.map->fillLevels(0, obj.map->levels() - 1);
        instructions += obj.map->fillStats().programRuns * obj.staticKernel->instructionCount();
    }
    mesh->dynamicKernel = obj.dynamicKernel;
    obj.mesh = std::move(mesh);
    obj.diceHeight = camera.height;
    ++stats.staticRuns;
    stats.staticInstructions += instructions;
}

Image MultiphaseRenderer::renderFrame(int frame, const RenderOptions& options, FrameStats& stats,
                                      const ProgressFn& progress) {
    const SampleBuffer samples = renderSamples(frame, options, stats, progress);
    const auto start = Clock::now();
    Image image = resolvePixels(samples, options.filter);
    stats.wallSeconds += secondsSince(start);
    return image;
}

SampleBuffer MultiphaseRenderer::renderSamples(int frame, const RenderOptions& options,
                                               FrameStats& stats, const ProgressFn& progress) {
    const auto start = Clock::now();
    stats = FrameStats{};
    const RenderSettings& settings = scene_.settings;
    const FrameState frameState =
        frameStateAt(resources_, frame, options.width, options.height, options.samplesPerPixel);
    const int width = frameState.width, height = frameState.height, spp = frameState.spp;
    const float time = frameState.time;
    const CameraState& camera = frameState.camera;
    const size_t count = objects_.size();
    const std::vector<ObjectState>& states = frameState.objects;
    const std::vector<ShadingUniforms>& uniforms = frameState.uniforms;

    // Static phase where needed: new objects, views that left the range, a new image size.
    const auto staticStart = Clock::now();
    for (size_t i = 0; i < count; ++i) {
        ObjectData& obj = *objects_[i];
        const glm::vec3 forward =
            glm::normalize(glm::vec3(states[i].worldToObject * glm::vec4(camera.forward, 0.0f)));
        if (!obj.mesh || !obj.mesh->inRange(states[i].eye, forward) || obj.diceHeight != height)
            staticPhase(i, states[i], camera, uniforms[i], stats);
    }
    stats.staticSeconds = secondsSince(staticStart);

    // Dynamic TSI: warp and rasterize.
    auto stageStart = Clock::now();
    std::vector<WarpedVertices> warped(count);
    std::vector<RasterObject> raster(count);
    tbb::parallel_for(size_t{0}, count, [&](size_t i) {
        const FacetMesh& mesh = *objects_[i]->mesh;
        const FixedPointWarp warp(states[i].objectToWorld, camera, mesh.format);
        warp.warp(mesh.qx.data(), mesh.qy.data(), mesh.qz.data(), mesh.positionCount(), warped[i]);
    });
    // Whole clusters off screen, or facing away from the eye (closed opaque surfaces).
    std::vector<std::vector<uint8_t>> visible(count);
    tbb::parallel_for(size_t{0}, count, [&](size_t i) {
        const FacetMesh& mesh = *objects_[i]->mesh;
        const bool backFaces = objects_[i]->opaque && objects_[i]->closed;
        visible[i] = clusterVisibility(mesh, states[i], camera, backFaces);
    });
    for (size_t i = 0; i < count; ++i) {
        raster[i] = {objects_[i]->mesh.get(), &warped[i], objects_[i]->opaque,
                     objects_[i]->opaque && objects_[i]->closed, visible[i].data()};
        stats.facets += objects_[i]->mesh->facetCount();
        stats.verticesWarped += objects_[i]->mesh->positionCount();
        stats.facetBytes += objects_[i]->mesh->bytes();
    }
    stats.warpSeconds = secondsSince(stageStart);
    stageStart = Clock::now();
    SampleBuffer samples;
    samples.resize(width, height, spp);
    for (int py = 0; py < height; ++py)
        for (int px = 0; px < width; ++px)
            for (int k = 0; k < spp; ++k) {
                const size_t s = samples.index(px, py, k);
                samplePosition(options.seed, px, py, k, spp, samples.xy[2 * s],
                               samples.xy[2 * s + 1]);
            }
    FragmentBuffer fragments;
    RasterStats rs;
    rasterizeFacets(raster, samples, options_.raster, fragments, rs);
    stats.facetsRasterized = rs.facetsBinned;
    stats.fragments = rs.fragments;
    stats.rasterSeconds = secondsSince(stageStart);
    stageStart = Clock::now();
    if (progress) progress(1, 3);

    // Dynamic shading: every kept fragment, object by object, in chunks.
    const size_t slots = fragments.fragments.size();
    std::vector<uint32_t> objectStart(count + 1, 0);
    for (size_t s = 0; s < fragments.count.size(); ++s)
        for (int l = 0; l < fragments.count[s]; ++l)
            ++objectStart[fragments.fragments[s * fragments.layers + l].object + 1];
    for (size_t i = 0; i < count; ++i) objectStart[i + 1] += objectStart[i];
    std::vector<uint32_t> order(objectStart[count]);
    {
        std::vector<uint32_t> next(objectStart.begin(), objectStart.end() - 1);
        for (size_t s = 0; s < fragments.count.size(); ++s)
            for (int l = 0; l < fragments.count[s]; ++l) {
                const size_t slot = s * fragments.layers + l;
                order[next[fragments.fragments[slot].object]++] = static_cast<uint32_t>(slot);
            }
    }
    std::vector<float> color(slots * 3), opacity(slots * 3);
    struct Chunk {
        size_t object, begin, end;
    };
    std::vector<Chunk> chunks;
    for (size_t i = 0; i < count; ++i)
        for (size_t b = objectStart[i]; b < objectStart[i + 1]; b += kChunk)
            chunks.push_back({i, b, std::min<size_t>(b + kChunk, objectStart[i + 1])});
    tbb::enumerable_thread_specific<ChunkBuffers> buffers;
    tbb::enumerable_thread_specific<uint64_t> instructions(0), nonFinite(0);
    tbb::parallel_for(size_t{0}, chunks.size(), [&](size_t c) {
        const Chunk& chunk = chunks[c];
        const ObjectData& obj = *objects_[chunk.object];
        const FacetMesh& mesh = *obj.mesh;
        const VertexAttributes& attr = mesh.attributes;
        const size_t m = chunk.end - chunk.begin;
        const size_t channels = static_cast<size_t>(mesh.channels);
        ChunkBuffers& b = buffers.local();
        b.prepare(m, channels);
        const glm::vec3 eye = states[chunk.object].eye;
        for (size_t i = 0; i < m; ++i) {
            const Fragment& f = fragments.fragments[order[chunk.begin + i]];
            const uint32_t* a = &mesh.attributeIndex[3 * static_cast<size_t>(f.facet)];
            const float w0 = 1.0f - f.b1 - f.b2;
            auto lerp = [&](const std::vector<float>& row) {
                return w0 * row[a[0]] + f.b1 * row[a[1]] + f.b2 * row[a[2]];
            };
            for (int row : obj.geometryRows) {
                const int dst = row < VertexAttributes::U ? row : row + 3;
                b.batch.row(dst)[i] = lerp(attr.rows[static_cast<size_t>(row)]);
            }
            // P for I: interpolated from the facet's own vertex positions when the dynamic
            // part does not read P itself.
            glm::vec3 P;
            if (!attr.rows[VertexAttributes::Px].empty()) {
                P = glm::vec3(b.batch.row(0)[i], b.batch.row(1)[i], b.batch.row(2)[i]);
            } else {
                const uint32_t* p = &mesh.positionIndex[3 * static_cast<size_t>(f.facet)];
                P = w0 * mesh.format.dequantize(mesh.qx[p[0]], mesh.qy[p[0]], mesh.qz[p[0]]) +
                    f.b1 * mesh.format.dequantize(mesh.qx[p[1]], mesh.qy[p[1]], mesh.qz[p[1]]) +
                    f.b2 * mesh.format.dequantize(mesh.qx[p[2]], mesh.qy[p[2]], mesh.qz[p[2]]);
            }
            if (!attr.rows[VertexAttributes::Nx].empty()) {
                glm::vec3 N(b.batch.row(3)[i], b.batch.row(4)[i], b.batch.row(5)[i]);
                const float len = glm::length(N);
                if (len > 0.0f) N /= len;
                b.batch.row(3)[i] = N.x, b.batch.row(4)[i] = N.y, b.batch.row(5)[i] = N.z;
            }
            const glm::vec3 I = glm::normalize(P - eye);
            b.batch.row(15)[i] = I.x, b.batch.row(16)[i] = I.y, b.batch.row(17)[i] = I.z;
            if (obj.useMap) {
                // (chart, u, v) at the sample, and its screen derivatives from the facet's
                // own gradient (facets are sub-pixel: affine is exact enough).
                const ChartPoint& c0 = mesh.attributeChartPoint[a[0]];
                const ChartPoint& c1 = mesh.attributeChartPoint[a[1]];
                const ChartPoint& c2 = mesh.attributeChartPoint[a[2]];
                const uint32_t* pi = &mesh.positionIndex[3 * static_cast<size_t>(f.facet)];
                const WarpedVertices& wv = warped[chunk.object];
                const float x1 = (wv.x[pi[1]] - wv.x[pi[0]]) / 256.0f,
                            y1 = (wv.y[pi[1]] - wv.y[pi[0]]) / 256.0f;
                const float x2 = (wv.x[pi[2]] - wv.x[pi[0]]) / 256.0f,
                            y2 = (wv.y[pi[2]] - wv.y[pi[0]]) / 256.0f;
                const float det = x1 * y2 - x2 * y1;
                ProbeQuery& q = b.queries[i];
                q.chart = c0.chart;
                q.u = w0 * c0.u + f.b1 * c1.u + f.b2 * c2.u;
                q.v = w0 * c0.v + f.b1 * c1.v + f.b2 * c2.v;
                if (std::fabs(det) > 1e-12f) {
                    const float du1 = c1.u - c0.u, du2 = c2.u - c0.u, dv1 = c1.v - c0.v,
                                dv2 = c2.v - c0.v;
                    q.dudx = (du1 * y2 - du2 * y1) / det;
                    q.dudy = (du2 * x1 - du1 * x2) / det;
                    q.dvdx = (dv1 * y2 - dv2 * y1) / det;
                    q.dvdy = (dv2 * x1 - dv1 * x2) / det;
                } else {
                    q.dudx = q.dudy = q.dvdx = q.dvdy = 0.0f;
                }
            } else {
                for (size_t ch = 0; ch < channels; ++ch)
                    b.batch.out.channels[ch][i] =
                        lerp(attr.rows[VertexAttributes::kGeometryRows + ch]);
            }
        }
        if (obj.useMap && channels > 0) {
            b.probed.resize(m * channels);
            probeShaderMap(*obj.map, options_.probe, {b.queries.data(), m}, b.probed.data());
            for (size_t i = 0; i < m; ++i)
                for (size_t ch = 0; ch < channels; ++ch)
                    b.batch.out.channels[ch][i] = b.probed[i * channels + ch];
        }
        ShadingCounters counters;
        mesh.dynamicKernel->run(uniforms[chunk.object], b.batch.in, m, b.batch.out, b.workspace,
                                counters);
        instructions.local() += counters.instructions;
        for (size_t i = 0; i < m; ++i) {
            const size_t slot = order[chunk.begin + i];
            bool finite = true;
            for (int k = 0; k < 3; ++k)
                finite = finite && std::isfinite(b.batch.out.Ci[k][i]) &&
                         std::isfinite(b.batch.out.Oi[k][i]);
            if (!finite) ++nonFinite.local();
            for (int k = 0; k < 3; ++k) {
                color[3 * slot + k] = finite ? b.batch.out.Ci[k][i] : 0.0f;
                opacity[3 * slot + k] =
                    finite ? std::clamp(b.batch.out.Oi[k][i], 0.0f, 1.0f) : 1.0f;
            }
        }
    });
    for (uint64_t v : instructions) stats.shaderInstructions += v;
    for (uint64_t v : nonFinite) stats.nonFiniteSamples += v;
    stats.shadedPoints = order.size();
    stats.shadeSeconds = secondsSince(stageStart);
    if (progress) progress(2, 3);

    // Composite front to back over the background.
    tbb::parallel_for(size_t{0}, fragments.count.size(), [&](size_t s) {
        float C[3] = {0, 0, 0}, T[3] = {1, 1, 1};
        for (int l = 0; l < fragments.count[s]; ++l) {
            const size_t slot = s * fragments.layers + l;
            for (int k = 0; k < 3; ++k) {
                C[k] += T[k] * opacity[3 * slot + k] * color[3 * slot + k];
                T[k] *= 1.0f - opacity[3 * slot + k];
            }
        }
        float* out = &samples.rgba[4 * s];
        for (int k = 0; k < 3; ++k) out[k] = C[k] + T[k] * settings.background[k];
        out[3] = 1.0f - (T[0] + T[1] + T[2]) / 3.0f;
    });
    if (progress) progress(3, 3);
    stats.index = frame;
    stats.time = time;
    stats.samples = static_cast<uint64_t>(width) * height * spp;
    stats.wallSeconds = secondsSince(start);
    return samples;
}

}  // namespace mpshade
