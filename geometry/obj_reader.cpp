// obj_reader.cpp -- a strict OBJ reader with precise diagnostics.
//
// A hand-written reader rather than tinyobjloader: a user error must name file:line:col,
// and tinyobjloader accepts malformed numbers silently (as 0) and reports no positions.
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string_view>

#include "geometry/error.h"
#include "geometry/polygon_mesh.h"

namespace mpshade {
namespace {

class ObjLine {
  public:
    ObjLine(const std::string& path, int line, std::string_view text)
        : path_(path), line_(line), text_(text) {}

    // Next white-space separated word; empty at end of line.
    std::string_view word() {
        while (pos_ < text_.size() &&
               (text_[pos_] == ' ' || text_[pos_] == '\t' || text_[pos_] == '\r'))
            ++pos_;
        wordStart_ = pos_;
        while (pos_ < text_.size() && text_[pos_] != ' ' && text_[pos_] != '\t' &&
               text_[pos_] != '\r')
            ++pos_;
        return text_.substr(wordStart_, pos_ - wordStart_);
    }

    float number() {
        std::string_view w = word();
        if (w.empty()) fail("expected a number");
        std::string s(w);
        char* end = nullptr;
        double value = std::strtod(s.c_str(), &end);
        if (end == s.c_str() || *end != '\0') fail("expected a number, found '" + s + "'");
        if (!std::isfinite(value) || std::fabs(value) > 3.0e38)
            fail("coordinate '" + s + "' is not a finite float");
        return static_cast<float>(value);
    }

    [[noreturn]] void fail(const std::string& message) const {
        throw InputError({path_, line_, static_cast<int>(wordStart_) + 1, {}}, message);
    }

  private:
    const std::string& path_;
    int line_;
    std::string_view text_;
    size_t pos_ = 0;
    size_t wordStart_ = 0;
};

// One "v", "v/vt", "v//vn" or "v/vt/vn" index; negative indices count back from the end.
int resolveIndex(ObjLine& line, std::string_view text, size_t count, const char* what) {
    if (text.empty()) return -1;
    std::string s(text);
    char* end = nullptr;
    long value = std::strtol(s.c_str(), &end, 10);
    if (end == s.c_str() || *end != '\0')
        line.fail(std::string("malformed ") + what + " index '" + s + "'");
    long resolved = value > 0 ? value - 1 : static_cast<long>(count) + value;
    if (value == 0 || resolved < 0 || resolved >= static_cast<long>(count))
        line.fail(std::string(what) + " index " + s + " is out of range (" + std::to_string(count) +
                  " defined so far)");
    return static_cast<int>(resolved);
}

}  // namespace

PolygonMeshData readObjPolygons(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw InputError({path, 0, 0, {}}, "cannot open OBJ file");
    PolygonMeshData mesh;
    std::string text;
    int lineNo = 0;
    while (std::getline(in, text)) {
        ++lineNo;
        ObjLine line(path, lineNo, text);
        std::string_view kind = line.word();
        if (kind.empty() || kind[0] == '#') continue;
        if (kind == "v") {
            glm::vec3 p;
            p.x = line.number();
            p.y = line.number();
            p.z = line.number();
            mesh.positions.push_back(p);  // an optional w or vertex colour is ignored
        } else if (kind == "vn") {
            glm::vec3 n;
            n.x = line.number();
            n.y = line.number();
            n.z = line.number();
            mesh.normals.push_back(n);
        } else if (kind == "vt") {
            glm::vec2 t;
            t.x = line.number();
            t.y = line.number();
            mesh.texcoords.push_back(t);
        } else if (kind == "f") {
            int size = 0;
            for (std::string_view w = line.word(); !w.empty(); w = line.word()) {
                ObjCorner c;
                size_t s1 = w.find('/');
                c.position = resolveIndex(line, w.substr(0, s1), mesh.positions.size(), "vertex");
                if (c.position < 0) line.fail("a face corner needs a vertex index");
                if (s1 != std::string_view::npos) {
                    std::string_view rest = w.substr(s1 + 1);
                    size_t s2 = rest.find('/');
                    c.texcoord = resolveIndex(line, rest.substr(0, s2), mesh.texcoords.size(),
                                              "texture coordinate");
                    if (s2 != std::string_view::npos)
                        c.normal =
                            resolveIndex(line, rest.substr(s2 + 1), mesh.normals.size(), "normal");
                }
                mesh.corners.push_back(c);
                ++size;
            }
            if (size < 3)
                line.fail("a face needs at least 3 corners, this one has " + std::to_string(size));
            mesh.faceSizes.push_back(size);
        } else if (kind == "o" || kind == "g" || kind == "s" || kind == "usemtl" ||
                   kind == "mtllib" || kind == "l" || kind == "p") {
            continue;
        } else {
            line.fail("unknown OBJ record '" + std::string(kind) + "'");
        }
    }
    if (mesh.faceSizes.empty()) throw InputError({path, 0, 0, {}}, "the OBJ file has no faces");
    return mesh;
}

}  // namespace mpshade
