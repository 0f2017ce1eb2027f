#include "app/store_command.h"

#include <chrono>
#include <cstdio>
#include <ctime>

#include <unistd.h>
#include <nlohmann/json.hpp>

#include "app/frame_request.h"
#include "app/output_files.h"
#include "app/store_export.h"
#include "controller/multiphase_renderer.h"
#include "geometry/content_digest.h"
#include "geometry/error.h"
#include "shadermaps/tile_store.h"

namespace mpshade {
namespace {

std::shared_ptr<TileStore> storeNamed(const std::string& folder) {
    RunOptions run;
    run.store = folder;
    std::shared_ptr<TileStore> store = openStore(run);
    if (!store)
        throw InputError({"--store", 0, 0, {}},
                         "no store folder: name one with --store (MPSHADE_STORE is off or "
                         "neither XDG_CACHE_HOME nor HOME is set)");
    return store;
}

std::string megabytes(uint64_t bytes) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f MB", static_cast<double>(bytes) / (1 << 20));
    return text;
}

std::string ago(std::filesystem::file_time_type t) {
    const auto seconds = std::chrono::duration_cast<std::chrono::seconds>(
                             std::filesystem::file_time_type::clock::now() - t)
                             .count();
    char text[32];
    if (seconds < 120)
        std::snprintf(text, sizeof text, "%lld s ago", static_cast<long long>(seconds));
    else if (seconds < 7200)
        std::snprintf(text, sizeof text, "%lld min ago", static_cast<long long>(seconds / 60));
    else
        std::snprintf(text, sizeof text, "%.1f h ago", static_cast<double>(seconds) / 3600.0);
    return text;
}

int storeInfo(const StoreCommandOptions& options) {
    const std::shared_ptr<TileStore> store = storeNamed(options.store);
    const std::vector<StoredMapSummary> maps = store->maps();
    uint64_t tiles = 0, bytes = 0;
    for (const StoredMapSummary& m : maps) {
        tiles += m.tiles;
        bytes += m.bytes;
    }
    // Which build filled a map: only this one's are read ("?": not recorded).
    const std::string engine = engineDigest().hex();
    auto build = [&](const StoredMapSummary& m) {
        return m.info.engine.empty() ? "?" : m.info.engine == engine ? "this" : "other";
    };
    if (options.json) {
        nlohmann::json list = nlohmann::json::array();
        for (const StoredMapSummary& m : maps)
            list.push_back({{"digest", m.digest.hex()},
                            {"object", m.info.object},
                            {"shader", m.info.shader},
                            {"channels", m.info.channelNames},
                            {"half", m.info.halfPrecision},
                            {"tiles", m.tiles},
                            {"bytes", m.bytes},
                            {"engine", m.info.engine},
                            {"build", build(m)}});
        const nlohmann::json doc = {
            {"folder", store->root().string()}, {"maps", list}, {"tiles", tiles}, {"bytes", bytes}};
        std::printf("%s\n", doc.dump(2).c_str());
        return 0;
    }
    std::printf("store %s: %zu map(s), %llu tile(s), %s\n", store->root().c_str(), maps.size(),
                static_cast<unsigned long long>(tiles), megabytes(bytes).c_str());
    if (maps.empty()) return 0;
    std::printf("\n%-12s %-16s %-16s %8s %8s %10s %6s  %s\n", "map", "object", "shader", "channels",
                "tiles", "size", "build", "last used");
    // Most recently used first.
    for (auto it = maps.rbegin(); it != maps.rend(); ++it)
        std::printf("%-12.12s %-16.16s %-16.16s %8zu %8llu %10s %6s  %s\n",
                    it->digest.hex().c_str(), it->info.object.c_str(), it->info.shader.c_str(),
                    it->info.channelNames.size(), static_cast<unsigned long long>(it->tiles),
                    megabytes(it->bytes).c_str(), build(*it), ago(it->lastUsed).c_str());
    return 0;
}

int storeGc(const StoreCommandOptions& options) {
    if (options.maxMb < 0)
        throw InputError({"--max-mb", 0, 0, {}}, "name the size to keep the store under, in MB");
    const std::shared_ptr<TileStore> store = storeNamed(options.store);
    const uint64_t before = store->bytes();
    const uint64_t removed = store->gc(static_cast<uint64_t>(options.maxMb) << 20);
    // What is left, each map in one pack where it had many (TileStore::compact).
    size_t merged = 0, mapsMerged = 0;
    for (const StoredMapSummary& m : store->maps(false)) {
        const size_t packs = store->compact(m.digest);
        merged += packs;
        mapsMerged += packs > 0 ? 1 : 0;
    }
    std::printf("store %s: removed %s of %s (least recently used maps first); %s left",
                store->root().c_str(), megabytes(removed).c_str(), megabytes(before).c_str(),
                megabytes(store->bytes()).c_str());
    if (merged > 0) std::printf("; %zu packs of %zu maps merged, one a map", merged, mapsMerged);
    std::printf("\n");
    return 0;
}

int storeExport(const StoreCommandOptions& options) {
    if (options.object.empty())
        throw InputError({"--object", 0, 0, {}}, "name the object whose maps to export");
    if (options.outDir.empty()) throw InputError({"--out", 0, 0, {}}, "name the output folder");
    if (options.maxSize < 1 || options.maxSize > 8192)
        throw InputError({"--max-size", 0, 0, {}},
                         "expected 1..8192 texels, found " + std::to_string(options.maxSize));
    const Scene scene = loadScene(options.scene);
    const SceneObject* object = nullptr;
    for (const SceneObject& o : scene.objects)
        if (o.name == options.object) object = &o;
    if (!object)
        throw InputError({options.scene, 0, 0, "objects"},
                         "no object is named '" + options.object + "'");
    const std::shared_ptr<TileStore> store = storeNamed(options.store);
    // The object's maps, most recently used first (another representative view, a changed
    // shader or parameter each made another).
    std::vector<StoredMapSummary> maps;
    for (const StoredMapSummary& m : store->maps())
        if (m.info.object == object->name && m.info.shader == object->shaderName)
            maps.insert(maps.begin(), m);
    if (maps.empty())
        throw InputError({"--object", 0, 0, {}},
                         "the store " + store->root().string() + " holds no map of '" +
                             object->name + "' (render or bake the scene with this store first)");
    prepareOutputFolder(options.outDir);
    const MapExport done = exportStoredMap(*store, maps.front(), options.outDir, options.maxSize);
    std::printf("wrote %d chart(s) of %s (map %s, channels", done.charts, object->name.c_str(),
                maps.front().digest.hex().c_str());
    for (const std::string& c : maps.front().info.channelNames) std::printf(" %s", c.c_str());
    std::printf(
        " filled) to %s: %llu tile(s) from the store, %llu not filled (marked 0 in "
        "'filled')\n",
        options.outDir.c_str(), static_cast<unsigned long long>(done.tilesRead),
        static_cast<unsigned long long>(done.tilesMissing));
    if (maps.size() > 1)
        std::printf("(%zu older map(s) of %s are in the store too)\n", maps.size() - 1,
                    object->name.c_str());
    return 0;
}

}  // namespace

int runBakeCommand(const BakeCommandOptions& options) {
    if (options.run.noStore)
        throw InputError({"--no-store", 0, 0, {}}, "bake fills a store: --no-store leaves none");
    FrameRequestOptions ask{options.scene, options.frames, options.size, options.spp, options.seed};
    const FrameRequest request = loadFrameRequest(ask);
    std::shared_ptr<TileStore> store = openStore(options.run);
    if (!store) store = storeNamed("");
    MultiphaseOptions mo;
    mo.singlePhaseFrames = false;  // a frame the reference renders fills nothing
    mo.staticPhase.store = store;
    MultiphaseRenderer renderer(request.scene, mo);
    renderer.plan(request.first, request.last, request.render);
    const bool tty = !options.quiet && isatty(STDERR_FILENO);
    const auto start = std::chrono::steady_clock::now();
    Image image;
    for (int frame = request.first; frame < request.last; ++frame) {
        FrameStats stats;
        renderer.renderFrame(frame, request.render, stats, image);
        if (!options.quiet)
            std::fprintf(
                stderr,
                tty ? "\rbake: frame %d (%d of %d): %llu tile(s) filled, %llu from the store"
                    : "bake: frame %d (%d of %d): %llu tile(s) filled, %llu from the store\n",
                frame, frame - request.first + 1, request.last - request.first,
                static_cast<unsigned long long>(stats.staticWork.work.tilesFilled),
                static_cast<unsigned long long>(stats.staticWork.work.tilesLoaded));
    }
    if (tty) std::fprintf(stderr, "\n");
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    cleanUpStore(store, options.run, request.scene);
    if (!options.quiet) {
        std::printf("baked frames %d:%d of %s into %s in %.2f s\n", request.first, request.last,
                    options.scene.c_str(), store->root().c_str(), seconds);
        std::printf("%-20s %12s %12s\n", "object", "filled", "from store");
        for (size_t i = 0; i < renderer.objectCount(); ++i) {
            const ObjectReport& r = renderer.report(i);
            std::printf("%-20.20s %12llu %12llu\n", r.name.c_str(),
                        static_cast<unsigned long long>(r.staticCosts.tilesFilled),
                        static_cast<unsigned long long>(r.staticCosts.tilesLoaded));
        }
    }
    return 0;
}

int runStoreCommand(const StoreCommandOptions& options) {
    if (options.action == "info") return storeInfo(options);
    if (options.action == "gc") return storeGc(options);
    if (options.action == "export") return storeExport(options);
    throw InputError({"store", 0, 0, {}},
                     "unknown action '" + options.action + "' (expected info, gc or export)");
}

}  // namespace mpshade
