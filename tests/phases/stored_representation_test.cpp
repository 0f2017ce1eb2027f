// A representation's facets as stored: read back whole, and no damaged or made-up record
// read out of bounds (every truncation and a sweep of flipped bytes is refused or reads
// as a consistent mesh).
#include <gtest/gtest.h>

#include "phases/stored_representation.h"

namespace mpshade {
namespace {

ObjectRepresentation sample() {
    ObjectRepresentation rep;
    FacetMesh& m = rep.mesh;
    m.format.origin = {1, 2, 3};
    m.qx = {0, 10, 20, 30};
    m.qy = {5, 6, 7, 8};
    m.qz = {9, 9, 9, 9};
    m.positionIndex = {0, 1, 2, 1, 3, 2};
    m.attributeIndex = {0, 1, 2, 2, 1, 0};
    m.channels = 2;
    m.attributes.count = 3;
    m.attributes.rows.assign(VertexAttributes::kGeometryRows + 2, {});
    m.attributes.rows[VertexAttributes::Px] = {0.5f, 1.5f, 2.5f};
    m.attributes.rows[VertexAttributes::kGeometryRows] = {1, 2, 3};
    m.attributes.rows[VertexAttributes::kGeometryRows + 1] = {4, 5, 6};
    m.attributeChartPoint = {{0, 0.1f, 0.2f}, {0, 0.3f, 0.4f}, {1, 0.5f, 0.6f}};
    m.clusters = {{0, 2, {0, 0, 0}, 1.0f, {0, 0, 1}, 1.0f}};
    rep.maxEdgePixels = 0.75f;
    rep.charts = 2;
    rep.patches = 3;
    rep.cappedPatches = 1;
    return rep;
}

TEST(StoredRepresentation, ReadsBackWhatWasWritten) {
    const ObjectRepresentation rep = sample();
    ObjectRepresentation back;
    ASSERT_TRUE(unpackRepresentation(packRepresentation(rep), back));
    EXPECT_EQ(back.mesh.qx, rep.mesh.qx);
    EXPECT_EQ(back.mesh.positionIndex, rep.mesh.positionIndex);
    EXPECT_EQ(back.mesh.attributeIndex, rep.mesh.attributeIndex);
    EXPECT_EQ(back.mesh.attributes.rows, rep.mesh.attributes.rows);
    EXPECT_EQ(back.mesh.attributes.count, 3u);
    EXPECT_EQ(back.mesh.channels, 2);
    EXPECT_EQ(back.mesh.clusters.size(), 1u);
    EXPECT_EQ(back.mesh.format.origin.y, 2.0f);
    EXPECT_EQ(back.maxEdgePixels, 0.75f);
    EXPECT_EQ(back.patches, 3);
    EXPECT_EQ(back.cappedPatches, 1);
}

TEST(StoredRepresentation, DamagedRecordsAreRefusedOrConsistent) {
    const std::vector<unsigned char> bytes = packRepresentation(sample());
    for (size_t n = 0; n < bytes.size(); ++n) {
        ObjectRepresentation back;
        EXPECT_FALSE(unpackRepresentation({bytes.data(), n}, back)) << "cut at " << n;
    }
    int accepted = 0;
    for (size_t at = 0; at < bytes.size(); ++at)
        for (unsigned char flip : {0x01, 0x80, 0xff}) {
            std::vector<unsigned char> damaged = bytes;
            damaged[at] ^= flip;
            ObjectRepresentation back;
            if (!unpackRepresentation(damaged, back)) continue;
            ++accepted;  // a float changed: what is read must still be in bounds
            const FacetMesh& m = back.mesh;
            for (uint32_t i : m.positionIndex) ASSERT_LT(i, m.qx.size());
            for (uint32_t i : m.attributeIndex) ASSERT_LT(i, m.attributes.count);
        }
    EXPECT_GT(accepted, 0);  // flips inside floats read as other floats
}

}  // namespace
}  // namespace mpshade
