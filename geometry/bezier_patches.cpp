#include "geometry/bezier_patches.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include <glm/geometric.hpp>

#include "geometry/error.h"

namespace mpshade {
namespace {

void bernstein(float t, float b[4], float db[4]) {
    const float s = 1.0f - t;
    b[0] = s * s * s;
    b[1] = 3.0f * t * s * s;
    b[2] = 3.0f * t * t * s;
    b[3] = t * t * t;
    db[0] = -3.0f * s * s;
    db[1] = 3.0f * s * s - 6.0f * t * s;
    db[2] = 6.0f * t * s - 3.0f * t * t;
    db[3] = 3.0f * t * t;
}

void evalPatch(const glm::vec3* cp, float u, float v, glm::vec3& P, glm::vec3& du, glm::vec3& dv) {
    float bu[4], dbu[4], bv[4], dbv[4];
    bernstein(u, bu, dbu);
    bernstein(v, bv, dbv);
    P = du = dv = glm::vec3(0.0f);
    for (int r = 0; r < 4; ++r) {
        for (int c = 0; c < 4; ++c) {
            const glm::vec3& p = cp[4 * r + c];
            P += (bu[c] * bv[r]) * p;
            du += (dbu[c] * bv[r]) * p;
            dv += (bu[c] * dbv[r]) * p;
        }
    }
}

// Reads numbers from a patch file, tracking line numbers for diagnostics.
class PatchFileReader {
  public:
    explicit PatchFileReader(const std::string& path) : path_(path), in_(path) {
        if (!in_) throw InputError({path, 0, 0, {}}, "cannot open Bezier patch file");
    }

    double number(const char* what) {
        std::string tok = token(what);
        char* end = nullptr;
        double value = std::strtod(tok.c_str(), &end);
        if (end == tok.c_str() || *end != '\0' || !std::isfinite(value))
            fail(std::string("expected ") + what + ", found '" + tok + "'");
        return value;
    }

    long integer(const char* what) {
        double value = number(what);
        if (value != std::floor(value) || std::fabs(value) > 1e9)
            fail(std::string("expected ") + what + " to be a whole number");
        return static_cast<long>(value);
    }

    [[noreturn]] void fail(const std::string& message) const {
        throw InputError({path_, line_, 0, {}}, message);
    }

  private:
    std::string token(const char* what) {
        for (;;) {
            std::string tok;
            if (words_ >> tok) return tok;
            std::string text;
            if (!std::getline(in_, text))
                throw InputError({path_, line_, 0, {}},
                                 std::string("unexpected end of file, expected ") + what);
            ++line_;
            if (auto hash = text.find('#'); hash != std::string::npos) text.resize(hash);
            for (char& ch : text)
                if (ch == ',') ch = ' ';
            words_.clear();
            words_.str(text);
        }
    }

    std::string path_;
    std::ifstream in_;
    std::istringstream words_;
    int line_ = 0;
};

}  // namespace

SurfaceSample BezierPatches::evaluate(int chart, float u, float v) const {
    const glm::vec3* cp = &controlPoints[16 * static_cast<size_t>(chart)];
    SurfaceSample s;
    evalPatch(cp, u, v, s.P, s.dPdu, s.dPdv);
    glm::vec3 n = normalFromDerivatives(s.dPdu, s.dPdv, glm::vec3(0.0f));
    if (n == glm::vec3(0.0f)) {
        // A collapsed patch edge (the teapot's lid and bottom): the normal is the limit
        // from inside the patch, so take the frame a little towards the patch centre.
        const float eps = 1e-3f;
        glm::vec3 P2, du2, dv2;
        evalPatch(cp, u + eps * (0.5f - u) * 2.0f, v + eps * (0.5f - v) * 2.0f, P2, du2, dv2);
        n = normalFromDerivatives(du2, dv2, glm::vec3(0.0f, 1.0f, 0.0f));
    }
    s.N = s.Ng = n;
    s.s = u;
    s.t = v;
    return s;
}

Bounds3 BezierPatches::bounds() const {
    // The convex hull property: the control points bound the surface.
    Bounds3 b;
    for (const auto& p : controlPoints) b.extend(p);
    return b;
}

BezierPatches loadBezierPatches(const std::string& path) {
    PatchFileReader in(path);
    long patches = in.integer("the patch count");
    if (patches <= 0 || patches > 10'000'000) in.fail("the patch count must be in 1..10,000,000");
    std::vector<long> indices(static_cast<size_t>(patches) * 16);
    for (long& index : indices) index = in.integer("a control point index");
    long vertices = in.integer("the vertex count");
    if (vertices <= 0 || vertices > 100'000'000) in.fail("the vertex count must be in 1..100,000,000");
    std::vector<glm::vec3> points(static_cast<size_t>(vertices));
    for (auto& p : points) {
        p.x = static_cast<float>(in.number("a coordinate"));
        p.y = static_cast<float>(in.number("a coordinate"));
        p.z = static_cast<float>(in.number("a coordinate"));
    }
    BezierPatches result;
    result.controlPoints.reserve(indices.size());
    for (size_t i = 0; i < indices.size(); ++i) {
        if (indices[i] < 1 || indices[i] > vertices)
            throw InputError({path, 0, 0, {}}, "patch " + std::to_string(i / 16) +
                                                   " names control point " +
                                                   std::to_string(indices[i]) + ", outside 1.." +
                                                   std::to_string(vertices));
        result.controlPoints.push_back(points[static_cast<size_t>(indices[i] - 1)]);
    }
    return result;
}

}  // namespace mpshade
