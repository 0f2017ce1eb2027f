// Shader-map probes side by side with OpenImageIO's TextureSystem on the same data: the
// level-0 texels of one chart written as a tiled, mip-mapped texture with make_texture,
// the same lookups, the same filter modes, a warm cache, one thread each. Each pair reads
// Probe/<filter>/<n>ch/ours and .../OIIO; items/s is lookups/s, and err_vs_ewa is the
// mean absolute difference from our EWA probe (the quality reference) over the lookups.
#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <random>
#include <string>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/texture.h>
#include <benchmark/benchmark.h>

#include "geometry/ray_scene.h"
#include "scene/scene.h"
#include "scene/scene_state.h"
#include "scene/variability.h"
#include "shadermaps/probe.h"
#include "shading/factoring.h"
#include "shading/shader_compiler.h"

namespace mpshade {
namespace {

constexpr int kResolution = 1024;
constexpr size_t kQueries = 4096;

// A map with `channels` noise channels over a plane, its texture file, lookups, and EWA.
struct ProbeData {
    Surface surface = Plane{4.0f, 4.0f};
    FactoredShader factored;
    std::unique_ptr<ShaderKernel> kernel;
    std::unique_ptr<ShaderMap> map;
    std::string file;
    std::vector<ProbeQuery> isotropic, anisotropic;
    std::vector<float> ewaIso, ewaAniso;
    int channels;

    explicit ProbeData(int n) : channels(n) {
        std::string src = "surface p() { float acc = 0;\n";
        for (int c = 0; c < n; ++c)
            src += fmt::format("acc += noise(P * {}) * time;\n", 2.0 + 1.7 * c);
        src += "Ci = color(acc); }";
        FactorOptions storeAll;  // the map holds every noise, however cheap to repeat
        storeAll.storeAboveCost = 0;
        factored = factorShader(*compileShaderText("probe.sl", src), {}, storeAll);
        kernel = std::make_unique<ShaderKernel>(factored.staticPart);
        ShaderMapOptions options;
        options.resolution = kResolution;
        map = std::make_unique<ShaderMap>(surface, *kernel, ShadingUniforms{}, options);
        map->fillLevels(0, map->levels() - 1);
        // Level 0 as an image, then a tiled mip-mapped texture made from it.
        OIIO::ImageBuf image(OIIO::ImageSpec(kResolution, kResolution, n, OIIO::TypeDesc::FLOAT));
        std::vector<float> texel(static_cast<size_t>(n));
        for (int j = 0; j < kResolution; ++j)
            for (int i = 0; i < kResolution; ++i) {
                const TileKey key = map->tileOf(0, 0, i, j);
                map->texel(key, map->slotOf(key), i, j, texel.data());
                image.setpixel(i, j, texel.data(), n);
            }
        file = (std::filesystem::temp_directory_path() / fmt::format("mpshade_probe_{}ch.tx", n))
                   .string();
        OIIO::ImageSpec config;
        config.format = OIIO::TypeDesc::FLOAT;
        OIIO::ImageBufAlgo::make_texture(OIIO::ImageBufAlgo::MakeTxTexture, image, file, config);

        std::mt19937 rng(7);
        std::uniform_real_distribution<float> pos(0.1f, 0.9f), size(0.0f, 4.0f), ratio(1.0f, 8.0f),
            angle(0.0f, 3.14159f);
        for (size_t k = 0; k < kQueries; ++k) {
            const float u = pos(rng), v = pos(rng), s = std::exp2(size(rng)) / kResolution;
            isotropic.push_back({0, u, v, s, 0.0f, 0.0f, s});
            const float r = ratio(rng), a = angle(rng), c = std::cos(a), sn = std::sin(a);
            anisotropic.push_back({0, u, v, s * r * c, s * r * sn, -s * sn, s * c});
        }
        ProbeOptions ewa;
        ewa.filter = ProbeFilter::EWA;
        ewaIso.resize(kQueries * static_cast<size_t>(n));
        ewaAniso.resize(kQueries * static_cast<size_t>(n));
        probeShaderMap(*map, ewa, isotropic, ewaIso.data());
        probeShaderMap(*map, ewa, anisotropic, ewaAniso.data());
    }

    double errorVsEwa(const std::vector<float>& result, bool aniso) const {
        const std::vector<float>& ref = aniso ? ewaAniso : ewaIso;
        double sum = 0.0;
        for (size_t i = 0; i < result.size(); ++i) sum += std::fabs(result[i] - ref[i]);
        return sum / static_cast<double>(result.size());
    }
};

ProbeData& data(int channels) {
    static std::map<int, std::unique_ptr<ProbeData>> cache;
    auto& d = cache[channels];
    if (!d) d = std::make_unique<ProbeData>(channels);
    return *d;
}

void ours(benchmark::State& state, ProbeFilter filter, int channels, float maxAnisotropy = 16.0f) {
    ProbeData& d = data(channels);
    const bool aniso = filter != ProbeFilter::Trilinear;
    const std::vector<ProbeQuery>& queries = aniso ? d.anisotropic : d.isotropic;
    ProbeOptions options;
    options.filter = filter;
    options.maxAnisotropy = maxAnisotropy;
    std::vector<float> out(queries.size() * static_cast<size_t>(channels));
    for (auto _ : state) {
        probeShaderMap(*d.map, options, queries, out.data());
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * queries.size()));
    state.counters["err_vs_ewa"] = d.errorVsEwa(out, aniso);
}

void oiio(benchmark::State& state, bool aniso, int channels) {
    ProbeData& d = data(channels);
    const std::vector<ProbeQuery>& queries = aniso ? d.anisotropic : d.isotropic;
    auto* ts = OIIO::TextureSystem::create(false);
    ts->attribute("max_memory_MB", 1024.0f);
    const OIIO::ustring name(d.file);
    OIIO::TextureSystem::TextureHandle* handle = ts->get_texture_handle(name);
    OIIO::TextureSystem::Perthread* perthread = ts->get_perthread_info();
    OIIO::TextureOpt opt;
    opt.mipmode = aniso ? OIIO::TextureOpt::MipModeAniso : OIIO::TextureOpt::MipModeTrilinear;
    opt.interpmode = OIIO::TextureOpt::InterpBilinear;
    opt.anisotropic = 16;
    opt.swrap = opt.twrap = OIIO::TextureOpt::WrapClamp;
    std::vector<float> out(queries.size() * static_cast<size_t>(channels));
    auto run = [&] {
        for (size_t k = 0; k < queries.size(); ++k) {
            const ProbeQuery& q = queries[k];
            ts->texture(handle, perthread, opt, q.u, q.v, q.dudx, q.dvdx, q.dudy, q.dvdy, channels,
                        out.data() + k * static_cast<size_t>(channels));
        }
    };
    run();  // warm the cache
    for (auto _ : state) {
        run();
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * queries.size()));
    state.counters["err_vs_ewa"] = d.errorVsEwa(out, aniso);
    OIIO::TextureSystem::destroy(ts);
}

// Tile fill: the static part of each example shader over the vase's 104 charts at 64 x 64
// texels (level 0 only: one texel, one program run), fresh map each iteration.
void tileFill(benchmark::State& state, const char* shader) {
    const Scene scene = loadScene(std::string(MPSHADE_SOURCE_DIR) + "/examples/vase/scene.json");
    SceneObject bound = scene.objects[0];
    bound.params.clear();
    const FactoredShader f = factorShader(
        *loadShaderFile(std::string(MPSHADE_SOURCE_DIR) + "/examples/shaders/" + shader + ".sl"),
        bindingOf(scene, bound));
    const ShaderKernel kernel(f.staticPart);
    const SurfaceRayScene rays(*bound.surface);
    const CameraState camera = cameraAt(scene, 0.0f, 480, 270);
    const ObjectState st = objectAt(bound, 0.0f, camera);
    std::vector<LightSample> lights;
    lightsAt(scene, st, 0.0f, lights);
    ShadingUniforms uniforms;
    uniforms.eye = st.eye;
    uniforms.lights = lights;
    uniforms.occluder = &rays;
    uniforms.occlusionBias = 1e-4f * surfaceBounds(*bound.surface).diagonal();
    ShaderMapOptions options;
    options.resolution = 64;
    options.alwaysResidentLevels = 0;
    uint64_t texels = 0;
    for (auto _ : state) {
        ShaderMap map(*bound.surface, kernel, uniforms, options);
        map.fillLevels(0, 0);
        texels += map.fillStats().texels;
    }
    state.SetItemsProcessed(static_cast<int64_t>(texels));
    state.counters["channels"] = f.chosenWidth;
}

BENCHMARK_CAPTURE(tileFill, marble, "marble")
    ->Name("TileFill/marble")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(tileFill, wood, "wood")
    ->Name("TileFill/wood")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(tileFill, brick, "brick")
    ->Name("TileFill/brick")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(tileFill, rust, "rust_over_paint")
    ->Name("TileFill/rust_over_paint")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(tileFill, plastic, "plastic")
    ->Name("TileFill/plastic")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

#define MPSHADE_PROBE_PAIR(n)                                                            \
    BENCHMARK_CAPTURE(ours, tri##n, ProbeFilter::Trilinear, n)                           \
        ->Name("Probe/Trilinear/" #n "ch/ours");                                         \
    BENCHMARK_CAPTURE(oiio, tri##n, false, n)->Name("Probe/Trilinear/" #n "ch/OIIO");    \
    BENCHMARK_CAPTURE(ours, feline##n, ProbeFilter::Feline, n)                           \
        ->Name("Probe/Anisotropic/" #n "ch/ours_feline");                                \
    BENCHMARK_CAPTURE(ours, feline4_##n, ProbeFilter::Feline, n, 4.0f)                   \
        ->Name("Probe/Anisotropic/" #n "ch/ours_feline_max4");                           \
    BENCHMARK_CAPTURE(oiio, aniso##n, true, n)->Name("Probe/Anisotropic/" #n "ch/OIIO"); \
    BENCHMARK_CAPTURE(ours, ewa##n, ProbeFilter::EWA, n)->Name("Probe/EWA/" #n "ch/ours");
MPSHADE_PROBE_PAIR(1)
MPSHADE_PROBE_PAIR(4)
MPSHADE_PROBE_PAIR(8)
#undef MPSHADE_PROBE_PAIR

}  // namespace
}  // namespace mpshade
