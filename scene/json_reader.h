// json_reader.h -- typed access to a parsed JSON document that knows where it is, so every
// error names the file and the JSON path ("objects[2].geometry.radius") and says what was
// expected. Unknown keys are errors (scene-format.md: "Unknown keys are an error").
#pragma once

#include <initializer_list>
#include <optional>
#include <span>
#include <string>

#include <glm/vec3.hpp>
#include <nlohmann/json_fwd.hpp>

#include "geometry/error.h"

namespace mpshade {

class JsonNode {
  public:
    JsonNode(const nlohmann::json& value, std::string file, std::string path)
        : value_(&value), file_(std::move(file)), path_(std::move(path)) {}

    const std::string& path() const { return path_; }
    const std::string& file() const { return file_; }
    const nlohmann::json& raw() const { return *value_; }

    bool isObject() const;
    bool isArray() const;
    bool isNumber() const;
    bool has(const char* key) const;

    JsonNode operator[](const char* key) const;  // required member of an object
    std::optional<JsonNode> optional(const char* key) const;
    size_t size() const;              // array length (requires an array)
    JsonNode at(size_t index) const;  // array element

    // Fails unless this is an object whose keys are all in `allowed`.
    void allowKeys(std::initializer_list<const char*> allowed) const;
    void allowKeys(std::span<const char* const> allowed) const;

    double number() const;  // finite
    double positive() const;
    double nonNegative() const;
    int integer(int lo, int hi) const;
    std::string string() const;
    glm::vec3 vec3() const;  // [x, y, z], finite
    bool boolean() const;

    [[noreturn]] void fail(const std::string& message) const;

  private:
    const nlohmann::json* value_;
    std::string file_;
    std::string path_;
};

// A number as a person writes it: 0.5, 1e-06, 12.
std::string shortNumber(double value);

// Arrays and objects nested deeper than this are an error (file:line:col of the first
// bracket too deep).
inline constexpr int kMaxJsonNesting = 64;

// Parses a JSON file; syntax errors name file:line:col.
nlohmann::json parseJsonFile(const std::string& path);

}  // namespace mpshade
