// output_files.h -- files a command writes are never half-written: each is written under a
// temporary name beside it and renamed over the final name once complete, so a reader (or
// a render stopped by Ctrl-C, a full disk or a crash) sees the old file or the new one.
#pragma once

#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>

namespace mpshade {

// Writing a file failed after the output folder was found writable (a full disk, an I/O
// error): the CLI reports it with exit status 1, naming the file.
class OutputError : public std::runtime_error {
  public:
    OutputError(const std::string& file, const std::string& reason)
        : std::runtime_error("cannot write " + file + ": " + reason) {}
};

// Creates `folder` if missing and checks a file can be created in it. Throws InputError
// naming the folder (a bad path: exit status 2) when it cannot.
void prepareOutputFolder(const std::filesystem::path& folder);

// Calls write(temporaryPath), which must create that file completely or throw, then
// renames it to `path`. On any failure the temporary file is removed and OutputError names
// `path`.
void writeAtomically(const std::filesystem::path& path,
                     const std::function<void(const std::string& temporaryPath)>& write);

// A whole text file, atomically.
void writeTextFile(const std::filesystem::path& path, const std::string& text);

}  // namespace mpshade
