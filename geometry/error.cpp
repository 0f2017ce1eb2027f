#include "geometry/error.h"

#include <cstdio>
#include <cstdlib>

namespace mpshade {

std::string InputLocation::str() const {
    std::string s = file.empty() ? std::string("<input>") : file;
    if (line > 0) {
        s += ":" + std::to_string(line);
        if (column > 0) s += ":" + std::to_string(column);
    }
    if (!jsonPath.empty()) s += ": " + jsonPath;
    return s;
}

InputError::InputError(InputLocation where, const std::string& message)
    : std::runtime_error(where.str() + ": error: " + message),
      where_(std::move(where)),
      message_(message) {}

void checkFailed(const char* expr, const char* file, int line) {
    std::fprintf(stderr, "mpshade internal error: check failed: %s (%s:%d)\n", expr, file, line);
    std::abort();
}

}  // namespace mpshade
