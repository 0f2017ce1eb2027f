// run_options.h -- what every rendering command (render, play, profile, eval, bake) shares
// about where it runs: the shader-map store it reads and adds to (docs/store.md), and how
// many threads it uses.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

namespace CLI {
class App;
}

namespace mpshade {

class TileStore;
struct Scene;

struct RunOptions {
    // The store's folder; empty: defaultStoreFolder() (tile_store.h).
    std::string store;
    bool noStore = false;  // fill every tile, read and write no store
    // The store's size budget, MB: after a run that wrote to it, maps unused longest are
    // removed until it fits. 0: 8192.
    int64_t storeMb = 0;
    int threads = 0;  // 0: every core
};

// Adds --store, --no-store, --store-mb and --threads to `command`.
void addRunOptions(CLI::App& command, RunOptions& options);

// The store a command uses, opened (null with --no-store, when MPSHADE_STORE is "off", or
// when no default folder is known). Throws InputError naming --store when the folder cannot
// be used.
std::shared_ptr<TileStore> openStore(const RunOptions& options);

// What the run did with the store so far, for stats.json: its folder (null: none), tiles
// read, written, damaged (found, removed and filled again) and writes that failed.
nlohmann::json storeReport(const std::shared_ptr<TileStore>& store);

// After a run of `scene`: if it wrote to the store, removes maps unused longest while the
// store is over its budget; warns of damaged tiles found. A run that read no tile but
// stored some, where the store holds maps of the scene's objects that another build of
// mpshade filled, says so on stderr (they are never read: a tile is keyed by its engine).
void cleanUpStore(const std::shared_ptr<TileStore>& store, const RunOptions& options,
                  const Scene& scene);

// Runs `command` with at most options.threads threads (every core when 0). Throws
// InputError naming --threads when it is not in 0..1024.
int runWithThreads(const RunOptions& options, const std::function<int()>& command);

}  // namespace mpshade
