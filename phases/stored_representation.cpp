#include "phases/stored_representation.h"

#include <cstring>
#include <type_traits>

namespace mpshade {
namespace {

constexpr uint32_t kVersion = 1;

class Writer {
  public:
    template <typename T>
    void value(const T& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        const auto* p = reinterpret_cast<const unsigned char*>(&v);
        out.insert(out.end(), p, p + sizeof(T));
    }
    template <typename T>
    void array(const std::vector<T>& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        value<uint64_t>(v.size());
        if (v.empty()) return;  // data() may be null
        const auto* p = reinterpret_cast<const unsigned char*>(v.data());
        out.insert(out.end(), p, p + v.size() * sizeof(T));
    }
    std::vector<unsigned char> out;
};

class Reader {
  public:
    explicit Reader(std::span<const unsigned char> b) : bytes(b) {}
    template <typename T>
    bool value(T& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        if (bytes.size() - at < sizeof(T)) return false;
        std::memcpy(&v, bytes.data() + at, sizeof(T));
        at += sizeof(T);
        return true;
    }
    template <typename T>
    bool array(std::vector<T>& v) {
        uint64_t n = 0;
        if (!value(n) || n > (bytes.size() - at) / sizeof(T)) return false;
        v.resize(n);
        if (n > 0) std::memcpy(v.data(), bytes.data() + at, n * sizeof(T));  // data() may be null
        at += n * sizeof(T);
        return true;
    }
    bool done() const { return at == bytes.size(); }

  private:
    std::span<const unsigned char> bytes;
    size_t at = 0;
};

}  // namespace

std::vector<unsigned char> packRepresentation(const ObjectRepresentation& rep) {
    Writer w;
    const FacetMesh& m = rep.mesh;
    w.value(kVersion);
    w.value(m.format);
    w.array(m.qx);
    w.array(m.qy);
    w.array(m.qz);
    w.array(m.positionIndex);
    w.array(m.attributeIndex);
    w.value<uint64_t>(m.attributes.count);
    w.value<uint64_t>(m.attributes.rows.size());
    for (const std::vector<float>& row : m.attributes.rows) w.array(row);
    w.array(m.attributeChartPoint);
    w.array(m.clusters);
    w.value<int32_t>(m.channels);
    w.value(rep.maxEdgePixels);
    for (int count :
         {rep.charts, rep.patches, rep.culledPatches, rep.frustumCulledPatches, rep.cappedPatches})
        w.value<int32_t>(count);
    return std::move(w.out);
}

bool unpackRepresentation(std::span<const unsigned char> bytes, ObjectRepresentation& rep) {
    Reader r(bytes);
    FacetMesh& m = rep.mesh;
    uint32_t version = 0;
    uint64_t count = 0, rows = 0;
    int32_t channels = 0;
    if (!r.value(version) || version != kVersion || !r.value(m.format) || !r.array(m.qx) ||
        !r.array(m.qy) || !r.array(m.qz) || !r.array(m.positionIndex) ||
        !r.array(m.attributeIndex) || !r.value(count) || !r.value(rows) || rows > 1024)
        return false;
    m.attributes.count = count;
    m.attributes.rows.assign(rows, {});
    for (std::vector<float>& row : m.attributes.rows)
        if (!r.array(row) || (!row.empty() && row.size() != count)) return false;
    int32_t counts[5];
    if (!r.array(m.attributeChartPoint) || !r.array(m.clusters) || !r.value(channels) ||
        !r.value(rep.maxEdgePixels))
        return false;
    for (int32_t& c : counts)
        if (!r.value(c)) return false;
    if (!r.done()) return false;
    // Consistent, so the dynamic phase reads nothing out of bounds.
    const size_t positions = m.qx.size(), facets = m.positionIndex.size() / 3;
    if (m.qy.size() != positions || m.qz.size() != positions || m.positionIndex.size() % 3 != 0 ||
        m.attributeIndex.size() != m.positionIndex.size() ||
        m.attributeChartPoint.size() != count || channels < 0 ||
        rows != VertexAttributes::kGeometryRows + static_cast<uint64_t>(channels))
        return false;
    for (uint32_t i : m.positionIndex)
        if (i >= positions) return false;
    for (uint32_t i : m.attributeIndex)
        if (i >= count) return false;
    for (const FacetCluster& c : m.clusters)
        if (c.firstFacet > facets || c.facetCount > facets - c.firstFacet) return false;
    m.channels = channels;
    rep.charts = counts[0];
    rep.patches = counts[1];
    rep.culledPatches = counts[2];
    rep.frustumCulledPatches = counts[3];
    rep.cappedPatches = counts[4];
    return true;
}

}  // namespace mpshade
