#include "scene/json_reader.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

namespace mpshade {
namespace {

const char* kindOf(const nlohmann::json& j) {
    switch (j.type()) {
        case nlohmann::json::value_t::null:
            return "null";
        case nlohmann::json::value_t::object:
            return "an object";
        case nlohmann::json::value_t::array:
            return "an array";
        case nlohmann::json::value_t::string:
            return "a string";
        case nlohmann::json::value_t::boolean:
            return "a boolean";
        case nlohmann::json::value_t::number_integer:
        case nlohmann::json::value_t::number_unsigned:
        case nlohmann::json::value_t::number_float:
            return "a number";
        default:
            return "a value";
    }
}

}  // namespace

void JsonNode::fail(const std::string& message) const {
    throw InputError({file_, 0, 0, path_.empty() ? std::string("(top level)") : path_}, message);
}

bool JsonNode::isObject() const {
    return value_->is_object();
}
bool JsonNode::isArray() const {
    return value_->is_array();
}
bool JsonNode::isNumber() const {
    return value_->is_number();
}
bool JsonNode::has(const char* key) const {
    return value_->is_object() && value_->contains(key);
}

JsonNode JsonNode::operator[](const char* key) const {
    if (!value_->is_object()) fail(std::string("expected an object, found ") + kindOf(*value_));
    auto it = value_->find(key);
    if (it == value_->end()) fail(std::string("missing required key '") + key + "'");
    return JsonNode(*it, file_, path_.empty() ? key : path_ + "." + key);
}

std::optional<JsonNode> JsonNode::optional(const char* key) const {
    if (!value_->is_object()) fail(std::string("expected an object, found ") + kindOf(*value_));
    auto it = value_->find(key);
    if (it == value_->end()) return std::nullopt;
    return JsonNode(*it, file_, path_.empty() ? key : path_ + "." + key);
}

size_t JsonNode::size() const {
    if (!value_->is_array()) fail(std::string("expected an array, found ") + kindOf(*value_));
    return value_->size();
}

JsonNode JsonNode::at(size_t index) const {
    size();
    return JsonNode((*value_)[index], file_, path_ + "[" + std::to_string(index) + "]");
}

void JsonNode::allowKeys(std::initializer_list<const char*> allowed) const {
    allowKeys(std::span<const char* const>(allowed.begin(), allowed.size()));
}

void JsonNode::allowKeys(std::span<const char* const> allowed) const {
    if (!value_->is_object()) fail(std::string("expected an object, found ") + kindOf(*value_));
    for (auto it = value_->begin(); it != value_->end(); ++it) {
        bool ok = false;
        for (const char* a : allowed) ok = ok || it.key() == a;
        if (!ok) {
            std::string list;
            for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
            JsonNode(*it, file_, path_.empty() ? it.key() : path_ + "." + it.key())
                .fail("unknown key '" + it.key() + "' (expected one of: " + list + ")");
        }
    }
}

double JsonNode::number() const {
    // nlohmann parses 1e999 to inf; NaN cannot be written in JSON but may come from it.
    if (!value_->is_number()) fail(std::string("expected a number, found ") + kindOf(*value_));
    const double v = value_->get<double>();
    if (!std::isfinite(v) || std::fabs(v) > 3.0e38) fail("expected a finite number");
    return v;
}

double JsonNode::positive() const {
    const double v = number();
    if (!(v > 0.0)) fail("expected a positive number, found " + value_->dump());
    return v;
}

double JsonNode::nonNegative() const {
    const double v = number();
    if (v < 0.0) fail("expected a non-negative number, found " + value_->dump());
    return v;
}

int JsonNode::integer(int lo, int hi) const {
    const double v = number();
    if (v != std::floor(v) || v < lo || v > hi)
        fail("expected a whole number in [" + std::to_string(lo) + ", " + std::to_string(hi) +
             "], found " + value_->dump());
    return static_cast<int>(v);
}

std::string JsonNode::string() const {
    if (!value_->is_string()) fail(std::string("expected a string, found ") + kindOf(*value_));
    return value_->get<std::string>();
}

bool JsonNode::boolean() const {
    if (!value_->is_boolean())
        fail(std::string("expected true or false, found ") + kindOf(*value_));
    return value_->get<bool>();
}

glm::vec3 JsonNode::vec3() const {
    if (!value_->is_array() || value_->size() != 3)
        fail(std::string("expected an array of 3 numbers, found ") +
             (value_->is_array() ? "an array of " + std::to_string(value_->size())
                                 : kindOf(*value_)));
    return glm::vec3(static_cast<float>(at(0).number()), static_cast<float>(at(1).number()),
                     static_cast<float>(at(2).number()));
}

std::string shortNumber(double value) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%g", value);
    return buffer;
}

namespace {

InputLocation locationOfByte(const std::string& path, const std::string& text, size_t byte) {
    if (byte > text.size()) byte = text.size();
    int line = 1, col = 1;
    for (size_t i = 0; i < byte; ++i) {
        if (text[i] == '\n') {
            ++line;
            col = 1;
        } else {
            ++col;
        }
    }
    return {path, line, col, {}};
}

// A scene nests five levels deep; anything near kMaxJsonNesting is a generated or hostile
// file, stopped before the parser builds it (and before anything walks it recursively).
void checkNesting(const std::string& path, const std::string& text) {
    int depth = 0;
    bool inString = false;
    for (size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (inString) {
            if (c == '\\')
                ++i;
            else if (c == '"')
                inString = false;
        } else if (c == '"') {
            inString = true;
        } else if (c == '[' || c == '{') {
            if (++depth > kMaxJsonNesting)
                throw InputError(locationOfByte(path, text, i),
                                 "invalid JSON: nested more than " +
                                     std::to_string(kMaxJsonNesting) + " levels deep");
        } else if (c == ']' || c == '}') {
            --depth;
        }
    }
}

}  // namespace

nlohmann::json parseJsonFile(const std::string& path) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
        throw InputError({path, 0, 0, {}}, "is a folder, not a scene file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError({path, 0, 0, {}}, "cannot open scene file");
    std::ostringstream buffer;
    buffer << in.rdbuf();
    const std::string text = buffer.str();
    checkNesting(path, text);
    try {
        return nlohmann::json::parse(text);
    } catch (const nlohmann::json::parse_error& e) {
        // e.byte is 1-based, at or just past the offending character.
        std::string what = e.what();
        if (auto pos = what.find("syntax error"); pos != std::string::npos) what = what.substr(pos);
        throw InputError(locationOfByte(path, text, e.byte > 0 ? e.byte - 1 : 0),
                         "invalid JSON: " + what);
    } catch (const nlohmann::json::out_of_range& e) {
        // "number overflow parsing '1e999'": point at the first occurrence of the literal.
        std::string what = e.what();
        if (auto pos = what.find("] "); pos != std::string::npos) what = what.substr(pos + 2);
        size_t byte = 0;
        if (auto q = what.find('\''); q != std::string::npos) {
            const std::string literal = what.substr(q + 1, what.rfind('\'') - q - 1);
            if (auto at = text.find(literal); at != std::string::npos) byte = at;
        }
        throw InputError(locationOfByte(path, text, byte),
                         "invalid JSON: " + what + " (numbers must be finite floats)");
    }
}

}  // namespace mpshade
