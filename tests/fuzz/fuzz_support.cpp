#include "fuzz/fuzz_support.h"

#include <filesystem>
#include <fstream>

#include <unistd.h>

namespace mpshade::fuzz {

const std::string& scenesFolder() {
    static const std::string folder = [] {
        namespace fs = std::filesystem;
        const fs::path root =
            fs::temp_directory_path() / ("mpshade-fuzz-" + std::to_string(::getpid()));
        const fs::path source = MPSHADE_SOURCE_DIR;
        fs::create_directories(root / "tests" / "data" / "scenes");
        std::error_code ec;
        fs::create_directory_symlink(source / "examples", root / "examples", ec);
        for (const char* sub : {"shaders", "meshes", "bad_shaders", "bad_scenes"})
            fs::create_directory_symlink(source / "tests" / "data" / sub,
                                         root / "tests" / "data" / sub, ec);
        return (root / "tests" / "data" / "scenes").string();
    }();
    return folder;
}

std::string writeInput(const std::string& name, const uint8_t* data, size_t size) {
    const std::string path = scenesFolder() + "/" + name;
    std::ofstream(path, std::ios::binary)
        .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    return path;
}

}  // namespace mpshade::fuzz
