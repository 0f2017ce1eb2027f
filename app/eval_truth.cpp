#include "app/eval_truth.h"

#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/output_files.h"
#include "geometry/error.h"

namespace mpshade {
namespace {

constexpr char kMagic[8] = {'M', 'P', 'T', 'R', 'U', 'T', 'H', '1'};

void hashBytes(uint64_t& h, const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) {
        h ^= p[i];
        h *= 1099511628211ull;
    }
}

std::string readBytes(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError({path.string(), 0, 0, {}}, "cannot read this file");
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::filesystem::path frameFile(const std::filesystem::path& folder, int frame) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%04d.f32", frame);
    return folder / name;
}

}  // namespace

uint64_t sceneContentHash(const std::string& scenePath) {
    uint64_t h = 14695981039346656037ull;
    const std::string text = readBytes(scenePath);
    hashBytes(h, text.data(), text.size());
    // The files it names, in the order the scene names them. A scene that does not parse is
    // left for the loader to report (it names the place).
    const nlohmann::json doc = nlohmann::json::parse(text, nullptr, false);
    if (doc.is_discarded() || !doc.is_object()) return h;
    const std::filesystem::path dir = std::filesystem::path(scenePath).parent_path();
    auto add = [&](const nlohmann::json& name) {
        if (!name.is_string()) return;
        const std::string bytes = readBytes(dir / name.get<std::string>());
        hashBytes(h, bytes.data(), bytes.size());
    };
    if (doc.contains("shaders") && doc["shaders"].is_object())
        for (const auto& item : doc["shaders"].items()) add(item.value());
    if (doc.contains("objects") && doc["objects"].is_array())
        for (const auto& object : doc["objects"])
            if (object.is_object() && object.contains("geometry") &&
                object["geometry"].is_object() && object["geometry"].contains("file"))
                add(object["geometry"]["file"]);
    return h;
}

std::filesystem::path TruthKey::folder(const std::filesystem::path& root) const {
    uint64_t h = sceneHash;
    const int32_t fields[4] = {width, height, samplesPerPixel, static_cast<int32_t>(seed)};
    hashBytes(h, fields, sizeof fields);
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
    return root / "truth" / hex;
}

std::optional<Image> readTruthFrame(const std::filesystem::path& folder, int frame, int width,
                                    int height) {
    std::ifstream in(frameFile(folder, frame), std::ios::binary);
    if (!in) return std::nullopt;
    char magic[8];
    int32_t size[2];
    if (!in.read(magic, sizeof magic) || std::memcmp(magic, kMagic, sizeof magic) != 0 ||
        !in.read(reinterpret_cast<char*>(size), sizeof size) || size[0] != width ||
        size[1] != height)
        return std::nullopt;
    Image image(width, height);
    if (!in.read(reinterpret_cast<char*>(image.rgba.data()),
                 static_cast<std::streamsize>(image.rgba.size() * sizeof(float))))
        return std::nullopt;
    return image;
}

void writeTruthFrame(const std::filesystem::path& folder, int frame, const Image& image) {
    std::filesystem::create_directories(folder);
    writeAtomically(frameFile(folder, frame), [&](const std::string& temporary) {
        std::ofstream out(temporary, std::ios::binary);
        const int32_t size[2] = {image.width, image.height};
        out.write(kMagic, sizeof kMagic);
        out.write(reinterpret_cast<const char*>(size), sizeof size);
        out.write(reinterpret_cast<const char*>(image.rgba.data()),
                  static_cast<std::streamsize>(image.rgba.size() * sizeof(float)));
        if (!out.flush()) throw std::runtime_error("write failed");
    });
}

}  // namespace mpshade
