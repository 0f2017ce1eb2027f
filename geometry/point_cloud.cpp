#include "geometry/point_cloud.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include <glm/geometric.hpp>

#include "geometry/error.h"

namespace mpshade {
namespace {
constexpr float kTwoPi = 6.28318530717958647692f;
}

void orthonormalBasis(const glm::vec3& n, glm::vec3& T, glm::vec3& B) {
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    const float b = n.x * n.y * a;
    T = glm::vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    B = glm::vec3(b, sign + n.y * n.y * a, -n.y);
}

SurfaceSample PointCloud::evaluate(int chart, float u, float v) const {
    const size_t k = static_cast<size_t>(chart);
    glm::vec3 T, B;
    orthonormalBasis(normals[k], T, B);
    const float r = radii[k];
    const float c = std::cos(kTwoPi * v), s = std::sin(kTwoPi * v);
    SurfaceSample out;
    out.P = centers[k] + (u * r) * (c * T + s * B);
    out.dPdu = r * (c * T + s * B);
    out.dPdv = (kTwoPi * u * r) * (-s * T + c * B);
    out.N = out.Ng = normals[k];
    out.s = u;
    out.t = v;
    return out;
}

ChartPoint PointCloud::chartPointOf(int chart, const glm::vec3& p) const {
    const size_t k = static_cast<size_t>(chart);
    glm::vec3 T, B;
    orthonormalBasis(normals[k], T, B);
    const glm::vec3 d = p - centers[k];
    const float x = glm::dot(d, T), y = glm::dot(d, B);
    float v = std::atan2(y, x) / kTwoPi;
    if (v < 0.0f) v += 1.0f;
    return {chart, std::fmin(std::sqrt(x * x + y * y) / radii[k], 1.0f), std::fmin(v, 1.0f)};
}

Bounds3 PointCloud::bounds() const {
    Bounds3 b;
    for (size_t k = 0; k < centers.size(); ++k) {
        b.extend(centers[k] - glm::vec3(radii[k]));
        b.extend(centers[k] + glm::vec3(radii[k]));
    }
    return b;
}

PointCloud loadPointCloud(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw InputError({path, 0, 0, {}}, "cannot open point file");
    PointCloud cloud;
    std::string text;
    int lineNo = 0;
    while (std::getline(in, text)) {
        ++lineNo;
        if (auto hash = text.find('#'); hash != std::string::npos) text.resize(hash);
        std::istringstream words(text);
        float f[7];
        int count = 0;
        std::string word;
        while (words >> word) {
            if (count == 7)
                throw InputError({path, lineNo, 0, {}},
                                 "expected 7 numbers (x y z nx ny nz radius), found more");
            char* end = nullptr;
            double value = std::strtod(word.c_str(), &end);
            if (end == word.c_str() || *end != '\0' || !std::isfinite(value) ||
                std::fabs(value) > 3.0e38)
                throw InputError({path, lineNo, 0, {}}, "'" + word + "' is not a finite number");
            f[count++] = static_cast<float>(value);
        }
        if (count == 0) continue;
        if (count != 7)
            throw InputError(
                {path, lineNo, 0, {}},
                "expected 7 numbers (x y z nx ny nz radius), found " + std::to_string(count));
        glm::vec3 n(f[3], f[4], f[5]);
        if (!(glm::length(n) > 0.0f)) throw InputError({path, lineNo, 0, {}}, "the normal is zero");
        if (!(f[6] > 0.0f)) throw InputError({path, lineNo, 0, {}}, "the radius must be positive");
        cloud.centers.emplace_back(f[0], f[1], f[2]);
        cloud.normals.push_back(glm::normalize(n));
        cloud.radii.push_back(f[6]);
    }
    if (cloud.centers.empty()) throw InputError({path, 0, 0, {}}, "the point file has no points");
    return cloud;
}

}  // namespace mpshade
