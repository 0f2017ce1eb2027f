#include "app/run_options.h"

#include <cstdio>
#include <cstdlib>
#include <set>
#include <string_view>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>
#include <CLI/CLI.hpp>

#include "geometry/content_digest.h"
#include "geometry/error.h"
#include "scene/scene.h"
#include "shadermaps/tile_store.h"

namespace mpshade {

void addRunOptions(CLI::App& command, RunOptions& options) {
    command.add_option("--store", options.store,
                       "Shader-map store folder: tiles are read from it and added to it "
                       "(default $MPSHADE_STORE, else ~/.cache/mpshade/store)");
    command.add_flag("--no-store", options.noStore,
                     "Fill every shader-map tile; read and write no store");
    command.add_option("--store-mb", options.storeMb,
                       "The store's size budget, MB: maps unused longest are removed past it "
                       "(default 8192)");
    command.add_option("--threads", options.threads, "Threads to use (default: every core)");
}

std::shared_ptr<TileStore> openStore(const RunOptions& options) {
    if (options.storeMb < 0 || options.storeMb > (int64_t{1} << 30))
        throw InputError({"--store-mb", 0, 0, {}},
                         "expected 0..1073741824 MB, found " + std::to_string(options.storeMb));
    if (options.noStore) return nullptr;
    std::filesystem::path folder = options.store;
    if (folder.empty()) {
        const char* env = std::getenv("MPSHADE_STORE");
        if (env && std::string_view(env) == "off") return nullptr;
        folder = defaultStoreFolder();
        if (folder.empty()) return nullptr;
    }
    try {
        return std::make_shared<TileStore>(folder);
    } catch (const InputError& e) {
        throw InputError({"--store", 0, 0, {}}, e.message() + ": " + folder.string());
    }
}

nlohmann::json storeReport(const std::shared_ptr<TileStore>& store) {
    if (!store) return {{"folder", nullptr}};
    const TileStoreCounters& c = store->counters();
    return {{"folder", store->root().string()},        {"tiles_read", c.loaded.load()},
            {"tiles_written", c.written.load()},       {"tiles_damaged", c.damaged.load()},
            {"records_read", c.recordsRead.load()},    {"records_written", c.recordsWritten.load()},
            {"write_failures", c.writeFailures.load()}};
}

void cleanUpStore(const std::shared_ptr<TileStore>& store, const RunOptions& options,
                  const Scene& scene) {
    if (!store) return;
    store->flush();  // the counters below include what was written behind
    const TileStoreCounters& c = store->counters();
    if (c.loaded.load() == 0 && c.written.load() > 0) {
        // Before clean-up, which may remove those maps as the ones unused longest.
        std::set<std::string> names;
        for (const SceneObject& o : scene.objects) names.insert(o.name);
        const std::string engine = engineDigest().hex();
        size_t others = 0;
        for (const StoredMapSummary& m : store->maps(false))
            others +=
                names.count(m.info.object) && !m.info.engine.empty() && m.info.engine != engine;
        if (others > 0)
            std::fprintf(stderr,
                         "mpshade: note: the store %s holds %zu map(s) of this scene's objects "
                         "that another build of mpshade filled; this build reads none of them "
                         "(tiles are keyed by the engine that filled them) and stored its own\n",
                         store->root().c_str(), others);
    }
    if (c.written.load() > 0) {
        store->compactWritten();
        store->gc(static_cast<uint64_t>(options.storeMb > 0 ? options.storeMb : 8192) << 20);
    }
    if (c.damaged.load() > 0)
        std::fprintf(stderr,
                     "mpshade: warning: %llu damaged tile(s) in the store %s were removed and "
                     "filled again\n",
                     static_cast<unsigned long long>(c.damaged.load()), store->root().c_str());
}

int runWithThreads(const RunOptions& options, const std::function<int()>& command) {
    if (options.threads < 0 || options.threads > 1024)
        throw InputError({"--threads", 0, 0, {}},
                         "expected 0..1024, found " + std::to_string(options.threads));
    if (options.threads == 0) return command();
    // The arena bounds this command's parallel loops; the global control, any arena made
    // inside it (a background filler's), and the stage limits read the arena's size.
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism,
                              static_cast<size_t>(options.threads));
    tbb::task_arena arena(options.threads);
    return arena.execute(command);
}

}  // namespace mpshade
