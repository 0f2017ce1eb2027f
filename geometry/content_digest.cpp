#include "geometry/content_digest.h"

#include <cstdio>
#include <vector>

#define XXH_INLINE_ALL
#include <xxhash.h>

#include "geometry/error.h"

namespace mpshade {

struct ContentHasher::State {
    XXH3_state_t xxh;
};

std::string Digest128::hex() const {
    char text[33];
    std::snprintf(text, sizeof text, "%016llx%016llx", static_cast<unsigned long long>(high),
                  static_cast<unsigned long long>(low));
    return text;
}

bool Digest128::fromHex(std::string_view text, Digest128& out) {
    if (text.size() != 32) return false;
    uint64_t part[2] = {0, 0};
    for (size_t i = 0; i < 32; ++i) {
        const char c = text[i];
        int v;
        if (c >= '0' && c <= '9')
            v = c - '0';
        else if (c >= 'a' && c <= 'f')
            v = c - 'a' + 10;
        else
            return false;
        part[i / 16] = (part[i / 16] << 4) | static_cast<uint64_t>(v);
    }
    out = {part[0], part[1]};
    return true;
}

ContentHasher::ContentHasher() : state_(std::make_unique<State>()) {
    XXH3_128bits_reset(&state_->xxh);
}

ContentHasher::~ContentHasher() = default;

ContentHasher& ContentHasher::addBytes(const void* data, size_t bytes) {
    if (bytes > 0) XXH3_128bits_update(&state_->xxh, data, bytes);
    return *this;
}

ContentHasher& ContentHasher::addString(std::string_view s) {
    addU64(s.size());
    return addBytes(s.data(), s.size());
}

Digest128 ContentHasher::finish() const {
    const XXH128_hash_t h = XXH3_128bits_digest(&state_->xxh);
    return {h.high64, h.low64};
}

Digest128 digestFile(const std::string& path) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) throw InputError({path, 0, 0, ""}, "cannot be read");
    ContentHasher hasher;
    std::vector<char> buffer(1 << 16);
    size_t got;
    while ((got = std::fread(buffer.data(), 1, buffer.size(), f)) > 0)
        hasher.addBytes(buffer.data(), got);
    const bool failed = std::ferror(f) != 0;
    std::fclose(f);
    if (failed) throw InputError({path, 0, 0, ""}, "cannot be read");
    return hasher.finish();
}

const Digest128& engineDigest() {
    static const Digest128 digest = [] {
        try {
            return digestFile("/proc/self/exe");
        } catch (const InputError&) {
            return Digest128{};
        }
    }();
    return digest;
}

uint64_t checksum64(const void* data, size_t bytes) {
    return XXH3_64bits(data, bytes);
}

}  // namespace mpshade
