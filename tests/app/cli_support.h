// cli_support.h -- running the mpshade binary as a user runs it, for the CLI tests.
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace mpshade::cli {

struct CliRun {
    int exitCode;
    std::string output;  // stdout and stderr
};

// Runs `mpshade ARGS` from the source folder (so examples/... resolve), 2>&1.
inline CliRun mpshade(const std::string& args) {
    const std::string command =
        "cd '" MPSHADE_SOURCE_DIR "' && '" MPSHADE_BINARY "' " + args + " 2>&1";
    FILE* pipe = popen(command.c_str(), "r");
    CliRun run{-1, ""};
    if (!pipe) return run;
    std::array<char, 4096> buffer;
    while (fgets(buffer.data(), buffer.size(), pipe)) run.output += buffer.data();
    const int status = pclose(pipe);
    run.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return run;
}

// An empty folder of its own under the test's temporary folder.
inline std::string tempDir(const std::string& name) {
    const std::string dir = ::testing::TempDir() + "mpshade_cli_" + name;
    std::filesystem::remove_all(dir);
    return dir;
}

// DIR/stats.json, parsed.
inline nlohmann::json readStats(const std::string& dir) {
    std::ifstream file(dir + "/stats.json");
    return nlohmann::json::parse(file);
}

}  // namespace mpshade::cli
