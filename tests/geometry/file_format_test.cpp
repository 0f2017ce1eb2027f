// Malformed geometry files give an InputError naming file:line(:col), never a crash.
#include <cstdio>
#include <fstream>

#include <gtest/gtest.h>

#include "geometry/bezier_patches.h"
#include "geometry/error.h"
#include "geometry/point_cloud.h"
#include "geometry/polygon_mesh.h"
#include "test_support.h"

namespace mpshade {
namespace {

std::string writeTemp(const std::string& name, const std::string& text) {
    const std::string path = ::testing::TempDir() + name;
    std::ofstream(path) << text;
    return path;
}

template <typename F>
InputError expectInputError(F&& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e;
    }
    ADD_FAILURE() << "expected an InputError";
    return InputError({}, "");
}

TEST(ObjReader, ReadsPositionsTexcoordsNormalsAndNegativeIndices) {
    const auto path = writeTemp(
        "ok.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf -3/1/1 -2/1/1 -1/1/1\n");
    const PolygonMeshData mesh = readObjPolygons(path);
    ASSERT_EQ(mesh.faceSizes.size(), 1u);
    EXPECT_EQ(mesh.corners[0].position, 0);
    EXPECT_EQ(mesh.corners[2].position, 2);
    EXPECT_EQ(mesh.corners[1].texcoord, 0);
    EXPECT_EQ(mesh.corners[1].normal, 0);
}

TEST(ObjReader, NamesLineAndColumnOfBadInput) {
    struct Case {
        const char* text;
        int line, column;
        const char* message;
    } cases[] = {
        {"v 0 0 0\nv 1 x 0\n", 2, 5, "expected a number, found 'x'"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", 4, 7,
         "vertex index 4 is out of range (3 defined so far)"},
        {"v 0 0 0\nv 1 0 0\nf 1 2\n", 3, 6, "a face needs at least 3 corners, this one has 2"},
        {"v 0 0 nan\n", 1, 7, "coordinate 'nan' is not a finite float"},
        {"v 0 0 1e40\n", 1, 7, "coordinate '1e40' is not a finite float"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", 4, 7,
         "vertex index 0 is out of range (3 defined so far)"},
        {"v 0 0 0\nbogus 1\n", 2, 1, "unknown OBJ record 'bogus'"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/a 2 3\n", 4, 3, "malformed texture coordinate index 'a'"},
    };
    int k = 0;
    for (const Case& c : cases) {
        const auto path = writeTemp("bad" + std::to_string(k++) + ".obj", c.text);
        const InputError e = expectInputError([&] { readObjPolygons(path); });
        EXPECT_EQ(e.where().line, c.line) << c.text;
        EXPECT_EQ(e.where().column, c.column) << c.text;
        EXPECT_EQ(e.message(), c.message);
        EXPECT_EQ(e.where().file, path);
    }
}

TEST(ObjReader, RejectsMissingAndEmptyFiles) {
    EXPECT_EQ(expectInputError([] { readObjPolygons("/nonexistent/x.obj"); }).message(),
              "cannot open OBJ file");
    const auto path = writeTemp("empty.obj", "# nothing\nv 0 0 0\n");
    EXPECT_EQ(expectInputError([&] { readObjPolygons(path); }).message(),
              "the OBJ file has no faces");
}

TEST(PolygonMesh, DropsZeroAreaFaces) {
    const auto path =
        writeTemp("degenerate.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n");
    const PolygonMesh mesh(readObjPolygons(path));
    EXPECT_EQ(mesh.chartCount(), 1);
    EXPECT_EQ(mesh.droppedFaces(), 1);
}

TEST(BezierFile, NamesLineOfBadInput) {
    const auto path =
        writeTemp("bad.patches", "1\n1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16\n16\n0 0 zero\n");
    const InputError e = expectInputError([&] { loadBezierPatches(path); });
    EXPECT_EQ(e.where().line, 4);
    EXPECT_EQ(e.message(), "expected a coordinate, found 'zero'");
    const auto range =
        writeTemp("range.patches", "1\n1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,99\n16\n" +
                                       std::string(16 * 6, ' ') + "\n");
    EXPECT_NE(
        expectInputError([&] { loadBezierPatches(range); }).message().find("expected a coordinate"),
        std::string::npos);
    const auto truncated = writeTemp("trunc.patches", "2\n1,2,3\n");
    EXPECT_EQ(expectInputError([&] { loadBezierPatches(truncated); }).message(),
              "unexpected end of file, expected a control point index");
}

TEST(PointFile, NamesLineOfBadInput) {
    struct Case {
        const char* text;
        int line;
        const char* message;
    } cases[] = {
        {"0 0 0 0 1 0 1\n0 0 0 0 0 0 1\n", 2, "the normal is zero"},
        {"0 0 0 0 1 0 -1\n", 1, "the radius must be positive"},
        {"0 0 0 0 1 0\n", 1, "expected 7 numbers (x y z nx ny nz radius), found 6"},
        {"0 0 0 0 1 0 1 5\n", 1, "expected 7 numbers (x y z nx ny nz radius), found more"},
        {"0 0 inf 0 1 0 1\n", 1, "'inf' is not a finite number"},
    };
    int k = 0;
    for (const Case& c : cases) {
        const auto path = writeTemp("bad" + std::to_string(k++) + ".pts", c.text);
        const InputError e = expectInputError([&] { loadPointCloud(path); });
        EXPECT_EQ(e.where().line, c.line);
        EXPECT_EQ(e.message(), c.message);
    }
}

}  // namespace
}  // namespace mpshade
