#include "app/oiio_loader.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

namespace mpshade {
namespace {

constexpr const char* kModuleName = "mpshade_oiio.so";

std::vector<std::filesystem::path> candidates() {
    std::vector<std::filesystem::path> paths;
    if (const char* path = std::getenv("MPSHADE_OIIO_PLUGIN"); path && *path) {
        paths.emplace_back(path);
        return paths;
    }
    std::error_code ec;
    const std::filesystem::path exe = std::filesystem::canonical("/proc/self/exe", ec);
    if (ec) return paths;
    const std::filesystem::path bin = exe.parent_path();
    paths.push_back(bin / kModuleName);
    // MPSHADE_PLUGIN_DIR_FROM_BIN: the install's module folder relative to its binary folder
    // (app/CMakeLists.txt), e.g. "../lib/mpshade".
    paths.push_back((bin / MPSHADE_PLUGIN_DIR_FROM_BIN / kModuleName).lexically_normal());
    return paths;
}

const MpshadeOiioPlugin* load(std::string& tried) {
    for (const std::filesystem::path& path : candidates()) {
        void* module = dlopen(path.c_str(), RTLD_LAZY | RTLD_LOCAL);
        if (!module) {
            const char* why = dlerror();  // names the path
            tried += "\n  " + (why ? std::string(why) : path.string() + ": cannot be loaded");
            continue;
        }
        const auto entry = reinterpret_cast<MpshadeOiioEntry>(dlsym(module, kMpshadeOiioEntry));
        const MpshadeOiioPlugin* plugin = entry ? entry() : nullptr;
        if (plugin && plugin->version == kMpshadeOiioPluginVersion) return plugin;
        tried += "\n  " + path.string() + ": not this mpshade's module (another version)";
        dlclose(module);
    }
    return nullptr;
}

}  // namespace

const MpshadeOiioPlugin& oiioPlugin() {
    static std::once_flag once;
    static const MpshadeOiioPlugin* plugin = nullptr;
    static std::string tried;
    std::call_once(once, [] { plugin = load(tried); });
    if (!plugin)
        throw std::runtime_error(
            "cannot load mpshade's OpenImageIO module, which reading images and exporting the "
            "store need (set MPSHADE_OIIO_PLUGIN to its path); tried:" +
            tried);
    return *plugin;
}

}  // namespace mpshade
