// error.h -- user-facing errors that name the place in the user's input.
//
// Two levels of errors, as in pbrt-v4: InputError is for bad user input (a scene, a
// shader, a mesh) and always names where the problem is; internal invariants use
// MPSHADE_CHECK and indicate a bug in mpshade itself.
#pragma once

#include <stdexcept>
#include <string>

namespace mpshade {

// Where in the user's input something is. Any field may be empty/zero when unknown.
struct InputLocation {
    std::string file;      // path as the user gave it
    int line = 0;          // 1-based; 0 = unknown
    int column = 0;        // 1-based; 0 = unknown
    std::string jsonPath;  // e.g. "objects[2].geometry.radius"; empty when not JSON

    // "file:line:col" or "file: objects[2].radius" -- the prefix of a diagnostic.
    std::string str() const;
};

// Bad user input. what() is the full one-line diagnostic: "<location>: error: <message>".
class InputError : public std::runtime_error {
  public:
    InputError(InputLocation where, const std::string& message);
    const InputLocation& where() const { return where_; }
    const std::string& message() const { return message_; }

  private:
    InputLocation where_;
    std::string message_;
};

[[noreturn]] void checkFailed(const char* expr, const char* file, int line);

}  // namespace mpshade

// Internal invariant; failure is a bug in mpshade, never a user error.
#define MPSHADE_CHECK(expr) ((expr) ? (void)0 : ::mpshade::checkFailed(#expr, __FILE__, __LINE__))
