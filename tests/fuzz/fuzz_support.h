// fuzz_support.h -- shared by the fuzz targets: a private folder laid out like the source
// tree (examples/ and tests/data/* linked to the real ones), so a fuzzed scene's relative
// paths ("../../../examples/shaders/plastic.sl", "../meshes/cube.obj") resolve as they do
// for the seed corpus, and a way to put fuzz input in a file the loaders can open.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace mpshade::fuzz {

// The private folder's tests/data/scenes (created on first use, one per process).
const std::string& scenesFolder();
// Writes data to `name` in scenesFolder(); returns its path.
std::string writeInput(const std::string& name, const uint8_t* data, size_t size);

}  // namespace mpshade::fuzz
