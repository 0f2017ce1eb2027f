// Fuzz target: the geometry readers. The first byte picks the reader (OBJ polygons, OBJ
// subdivision cage with Catmull-Clark or Loop, Bezier patches, points); the rest is the
// file. A file that loads is built into its surface and evaluated at every chart's centre
// and corner, and must give finite bounds.
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_support.h"
#include "geometry/error.h"
#include "geometry/surface.h"

namespace {

void probe(const mpshade::Surface& surface) {
    const int charts = mpshade::chartCount(surface);
    for (int c = 0; c < charts && c < 64; ++c)
        for (float u : {0.0f, 0.5f, 1.0f}) {
            const mpshade::SurfaceSample s = mpshade::evaluate(surface, {c, u, u});
            (void)s;
        }
    (void)mpshade::surfaceBounds(surface);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 1) return 0;
    const int kind = data[0] % 5;
    const char* names[] = {"fuzz.obj", "fuzz_cage.obj", "fuzz_loop.obj", "fuzz.bez", "fuzz.pts"};
    const std::string path = mpshade::fuzz::writeInput(names[kind], data + 1, size - 1);
    try {
        switch (kind) {
            case 0:
                probe(mpshade::Surface(mpshade::PolygonMesh(mpshade::readObjPolygons(path))));
                break;
            case 1:
            case 2:
                probe(mpshade::Surface(mpshade::SubdivSurface(
                    mpshade::loadObjCage(path),
                    kind == 1 ? mpshade::SubdivScheme::Catmark : mpshade::SubdivScheme::Loop,
                    path)));
                break;
            case 3:
                probe(mpshade::Surface(mpshade::loadBezierPatches(path)));
                break;
            default:
                probe(mpshade::Surface(mpshade::loadPointCloud(path)));
                break;
        }
    } catch (const mpshade::InputError&) {
    }
    return 0;
}
