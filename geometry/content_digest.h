// content_digest.h -- 128-bit digests of content (XXH3), for what is addressed by what it
// was made from: a shader-map tile in the on-disk store (shadermaps/tile_store.h) is found
// by the digest of everything its texels depend on, so a change to any of it finds nothing
// rather than something stale. XXH3-128 is not cryptographic: it guards against accident
// (2^-128 per pair), not against a store written to collide on purpose.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

namespace mpshade {

struct Digest128 {
    uint64_t high = 0, low = 0;
    bool operator==(const Digest128&) const = default;
    std::string hex() const;  // 32 lowercase hex digits, high first
    // Parses 32 hex digits; false (and `out` untouched) otherwise.
    static bool fromHex(std::string_view text, Digest128& out);
};

// Streaming XXH3-128. Every add() is framed by nothing: callers add fixed-size values or
// say lengths (addString does), so two different sequences cannot hash the same bytes.
class ContentHasher {
  public:
    ContentHasher();
    ~ContentHasher();
    ContentHasher(const ContentHasher&) = delete;
    ContentHasher& operator=(const ContentHasher&) = delete;

    ContentHasher& addBytes(const void* data, size_t bytes);
    ContentHasher& addU64(uint64_t v) { return addBytes(&v, sizeof v); }
    ContentHasher& addI32(int32_t v) { return addBytes(&v, sizeof v); }
    // Floats by their bits: -0 and 0 differ, as do NaNs of different payloads.
    ContentHasher& addFloat(float v) { return addBytes(&v, sizeof v); }
    ContentHasher& addString(std::string_view s);  // length, then bytes
    ContentHasher& addDigest(const Digest128& d) { return addU64(d.high).addU64(d.low); }
    Digest128 finish() const;

  private:
    struct State;
    std::unique_ptr<State> state_;
};

// The digest of a file's bytes. Throws InputError (geometry/error.h) naming the file when
// it cannot be read.
Digest128 digestFile(const std::string& path);

// The running program's own digest: of its executable's bytes (/proc/self/exe), read once.
// What is stored by content is keyed with it too, so a store is never read by a build that
// could evaluate a shader to other bits (another compiler, a changed noise function): any
// change to the engine is a new key. Zero where the executable cannot be read.
const Digest128& engineDigest();

// A 64-bit checksum of bytes (XXH3-64), for detecting a damaged copy.
uint64_t checksum64(const void* data, size_t bytes);

}  // namespace mpshade
