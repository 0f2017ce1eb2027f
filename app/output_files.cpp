#include "app/output_files.h"

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>

#include <unistd.h>

#include "geometry/error.h"

namespace mpshade {

void prepareOutputFolder(const std::filesystem::path& folder) {
    std::error_code ec;
    std::filesystem::create_directories(folder, ec);
    if (ec)
        throw InputError({folder.string(), 0, 0, {}},
                         "cannot create the output folder: " + ec.message());
    if (!std::filesystem::is_directory(folder, ec))
        throw InputError({folder.string(), 0, 0, {}}, "the output path is not a folder");
    const std::filesystem::path probe =
        folder / (".mpshade-write-test-" + std::to_string(::getpid()));
    std::FILE* f = std::fopen(probe.c_str(), "wb");
    if (!f)
        throw InputError({folder.string(), 0, 0, {}},
                         std::string("cannot write in the output folder: ") + std::strerror(errno));
    std::fclose(f);
    std::filesystem::remove(probe, ec);
}

void writeAtomically(const std::filesystem::path& path,
                     const std::function<void(const std::string& temporaryPath)>& write) {
    // Same folder (so the rename stays on one file system), a name no frame uses, nor another
    // process writing the same file (two renders into one folder, on one machine or on
    // several sharing it).
    static std::atomic<uint64_t> counter{0};
    char host[64] = "host";
    ::gethostname(host, sizeof host - 1);
    host[sizeof host - 1] = '\0';
    const std::filesystem::path temporary =
        path.parent_path() /
        ("." + path.filename().string() + "." + host + "." + std::to_string(::getpid()) + "." +
         std::to_string(counter++) + ".partial");
    std::error_code ec;
    try {
        write(temporary.string());
    } catch (const std::exception& e) {
        std::filesystem::remove(temporary, ec);
        throw OutputError(path.string(), e.what());
    }
    std::filesystem::rename(temporary, path, ec);
    if (ec) {
        const std::string reason = ec.message();  // before the removal resets ec
        std::filesystem::remove(temporary, ec);
        throw OutputError(path.string(), reason);
    }
}

void writeTextFile(const std::filesystem::path& path, const std::string& text) {
    writeAtomically(path, [&](const std::string& temporary) {
        std::ofstream out(temporary, std::ios::binary);
        out << text;
        out.close();
        if (!out) throw std::runtime_error(std::strerror(errno));
    });
}

}  // namespace mpshade
