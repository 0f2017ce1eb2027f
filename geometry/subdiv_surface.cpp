#include "geometry/subdiv_surface.h"

#include <cmath>

#include <opensubdiv/bfr/refinerSurfaceFactory.h>
#include <opensubdiv/bfr/surface.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <glm/geometric.hpp>

#include "geometry/error.h"
#include "geometry/polygon_mesh.h"

namespace mpshade {

using namespace OpenSubdiv;

struct SubdivSurface::Impl {
    struct Chart {
        int face;
        int patch;    // index into surfaces
        int subFace;  // -1: the whole face
        // Affine map from chart (u, v) to Bfr face coordinates: uv = origin + u*du + v*dv.
        float origin[2], du[2], dv[2];
    };
    SubdivScheme scheme;
    bool closed = false;
    std::vector<Bfr::Surface<float>> surfaces;
    std::vector<std::vector<float>> patchPoints;  // xyz per patch point, per surface
    std::vector<Chart> charts;
    Bounds3 bounds;
};

SubdivSurface::SubdivSurface(const SubdivCage& cage, SubdivScheme scheme, const std::string& source)
    : impl_(std::make_unique<Impl>()) {
    impl_->scheme = scheme;
    if (cage.positions.empty() || cage.faceSizes.empty())
        throw InputError({source, 0, 0, {}}, "the subdivision cage has no faces");
    for (size_t f = 0; f < cage.faceSizes.size(); ++f) {
        if (scheme == SubdivScheme::Loop && cage.faceSizes[f] != 3)
            throw InputError({source, 0, 0, {}},
                             "face " + std::to_string(f) + " has " +
                                 std::to_string(cage.faceSizes[f]) +
                                 " sides; the loop scheme takes triangles only");
    }
    Far::TopologyDescriptor desc;
    desc.numVertices = static_cast<int>(cage.positions.size());
    desc.numFaces = static_cast<int>(cage.faceSizes.size());
    desc.numVertsPerFace = cage.faceSizes.data();
    desc.vertIndicesPerFace = cage.faceIndices.data();

    Sdc::Options sdc;
    sdc.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
    using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
    Factory::Options options(scheme == SubdivScheme::Loop ? Sdc::SCHEME_LOOP : Sdc::SCHEME_CATMARK,
                             sdc);
    std::unique_ptr<Far::TopologyRefiner> refiner(Factory::Create(desc, options));
    if (!refiner) throw InputError({source, 0, 0, {}}, "OpenSubdiv rejected the cage topology");

    Bfr::RefinerSurfaceFactory<> factory(*refiner);
    const float* meshPoints = &cage.positions[0].x;
    for (int face = 0; face < desc.numFaces; ++face) {
        Bfr::Surface<float> surface;
        if (!factory.InitVertexSurface(face, &surface) || !surface.IsValid()) continue;  // hole
        std::vector<float> pts(static_cast<size_t>(surface.GetNumPatchPoints()) * 3);
        surface.PreparePatchPoints(meshPoints, 3, pts.data(), 3);
        const int patch = static_cast<int>(impl_->surfaces.size());
        Bfr::Parameterization param = surface.GetParameterization();
        if (param.HasSubFaces()) {
            for (int sub = 0; sub < param.GetFaceSize(); ++sub) {
                Impl::Chart c{face, patch, sub, {}, {}, {}};
                float s00[2] = {0, 0}, s10[2] = {1, 0}, s01[2] = {0, 1};
                float o[2], a[2], b[2];
                param.ConvertNormalizedSubFaceToCoord(sub, s00, o);
                param.ConvertNormalizedSubFaceToCoord(sub, s10, a);
                param.ConvertNormalizedSubFaceToCoord(sub, s01, b);
                for (int k = 0; k < 2; ++k) {
                    c.origin[k] = o[k];
                    c.du[k] = a[k] - o[k];
                    c.dv[k] = b[k] - o[k];
                }
                impl_->charts.push_back(c);
            }
        } else {
            impl_->charts.push_back({face, patch, -1, {0, 0}, {1, 0}, {0, 1}});
        }
        impl_->surfaces.push_back(std::move(surface));
        impl_->patchPoints.push_back(std::move(pts));
    }
    if (impl_->charts.empty())
        throw InputError({source, 0, 0, {}}, "no face of the cage has a limit surface");
    impl_->closed = cageIsClosed(cage.faceSizes, cage.faceIndices);
    // Limit points lie in the convex hull of the cage.
    for (const auto& p : cage.positions) impl_->bounds.extend(p);
}

SubdivSurface::~SubdivSurface() = default;
SubdivSurface::SubdivSurface(SubdivSurface&&) noexcept = default;
SubdivSurface& SubdivSurface::operator=(SubdivSurface&&) noexcept = default;

int SubdivSurface::chartCount() const {
    return static_cast<int>(impl_->charts.size());
}
int SubdivSurface::chartFace(int chart) const {
    return impl_->charts[chart].face;
}
bool SubdivSurface::closed() const {
    return impl_->closed;
}
Bounds3 SubdivSurface::bounds() const {
    return impl_->bounds;
}

SurfaceSample SubdivSurface::evaluate(int chart, float u, float v) const {
    const Impl::Chart& c = impl_->charts[static_cast<size_t>(chart)];
    const Bfr::Surface<float>& surface = impl_->surfaces[static_cast<size_t>(c.patch)];
    const float* pts = impl_->patchPoints[static_cast<size_t>(c.patch)].data();

    // Chart (u, v) -> Bfr coordinates, and the chain rule for the derivatives.
    float uv[2], ju[2], jv[2];  // d(bfr uv)/du and /dv
    if (impl_->scheme == SubdivScheme::Loop) {
        uv[0] = u * (1.0f - v);
        uv[1] = v;
        ju[0] = 1.0f - v;
        ju[1] = 0.0f;
        jv[0] = -u;
        jv[1] = 1.0f;
    } else {
        for (int k = 0; k < 2; ++k) {
            uv[k] = c.origin[k] + u * c.du[k] + v * c.dv[k];
            ju[k] = c.du[k];
            jv[k] = c.dv[k];
        }
    }
    float P[3], Du[3], Dv[3];
    surface.Evaluate(uv, pts, 3, P, Du, Dv);
    const glm::vec3 du(Du[0], Du[1], Du[2]), dv(Dv[0], Dv[1], Dv[2]);
    SurfaceSample s;
    s.P = glm::vec3(P[0], P[1], P[2]);
    s.dPdu = ju[0] * du + ju[1] * dv;
    s.dPdv = jv[0] * du + jv[1] * dv;
    // The face's own frame gives the normal even where the chart collapses (Loop, v = 1).
    glm::vec3 n = normalFromDerivatives(du, dv, glm::vec3(0.0f));
    if (n == glm::vec3(0.0f)) {
        float inner[2] = {
            uv[0] + 1e-3f * ((impl_->scheme == SubdivScheme::Loop ? 1.0f / 3.0f : 0.5f) - uv[0]),
            uv[1] + 1e-3f * ((impl_->scheme == SubdivScheme::Loop ? 1.0f / 3.0f : 0.5f) - uv[1])};
        float P2[3], Du2[3], Dv2[3];
        surface.Evaluate(inner, pts, 3, P2, Du2, Dv2);
        n = normalFromDerivatives(glm::vec3(Du2[0], Du2[1], Du2[2]),
                                  glm::vec3(Dv2[0], Dv2[1], Dv2[2]), glm::vec3(0, 1, 0));
    }
    s.N = s.Ng = n;
    s.s = u;
    s.t = v;
    return s;
}

SubdivCage loadObjCage(const std::string& path) {
    PolygonMeshData data = readObjPolygons(path);
    SubdivCage cage;
    cage.positions = std::move(data.positions);
    cage.faceSizes = std::move(data.faceSizes);
    cage.faceIndices.reserve(data.corners.size());
    for (const auto& corner : data.corners) cage.faceIndices.push_back(corner.position);
    return cage;
}

}  // namespace mpshade
