#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "ExportTestMap.hpp"
#include "strata/core/Error.hpp"
#include "strata/io/PlyExport.hpp"

namespace strata::io {
namespace {

using namespace export_test;

struct PlyFile {
    std::vector<std::string> header;  // lines up to and including end_header
    std::string body;
};

PlyFile ReadPly(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    PlyFile ply;
    for (std::string line; std::getline(in, line);) {
        ply.header.push_back(line);
        if (line == "end_header") break;
    }
    const std::streampos body_start = in.tellg();
    in.seekg(0, std::ios::end);
    ply.body.resize(static_cast<size_t>(in.tellg() - body_start));
    in.seekg(body_start);
    in.read(ply.body.data(), static_cast<std::streamsize>(ply.body.size()));
    return ply;
}

bool HasLine(const PlyFile& ply, const std::string& line) {
    for (const auto& l : ply.header) {
        if (l == line) return true;
    }
    return false;
}

uint64_t VertexCount(const PlyFile& ply) {
    for (const auto& l : ply.header) {
        if (l.rfind("element vertex ", 0) == 0) return std::stoull(l.substr(15));
    }
    return 0;
}

uint64_t OccupiedVoxels(const core::VoxelMap& map) {
    uint64_t n = 0;
    for (auto it = map.occupancy->cbeginValueOn(); it; ++it) {
        if (*it > 0.0f) n += it.getVoxelCount();
    }
    return n;
}

// Decodes every vertex (the host is little endian, as the file) and checks it against the map.
template <typename Real>
void ExpectVerticesMatchMap(const PlyFile& ply, const core::VoxelMap& map) {
    constexpr size_t kStride = 3 * sizeof(Real) + 4;
    const uint64_t n = VertexCount(ply);
    ASSERT_EQ(ply.body.size(), n * kStride);
    auto occupancy = map.occupancy->getConstAccessor();
    auto labels = map.label->getConstAccessor();
    for (uint64_t v = 0; v < n; ++v) {
        const char* rec = ply.body.data() + v * kStride;
        Real xyz[3];
        std::memcpy(xyz, rec, sizeof xyz);
        const auto* rgbl = reinterpret_cast<const uint8_t*>(rec + sizeof xyz);
        const Eigen::Vector3d p_map = Eigen::Vector3d(xyz[0], xyz[1], xyz[2]) - map.origin;
        const openvdb::Coord ijk = map.WorldToVoxel(p_map);
        ASSERT_TRUE((map.VoxelCenter(ijk) - p_map).norm() < 1e-4) << "not a voxel centre";
        ASSERT_GT(occupancy.getValue(ijk), 0.0f) << ijk;
        ASSERT_TRUE(occupancy.isValueOn(ijk)) << ijk;
        const auto c = static_cast<SemanticClass>(labels.getValue(ijk));
        const core::Rgb rgb = core::ClassColor(c);
        ASSERT_EQ(rgbl[0], rgb.r);
        ASSERT_EQ(rgbl[1], rgb.g);
        ASSERT_EQ(rgbl[2], rgb.b);
        ASSERT_EQ(rgbl[3], static_cast<uint8_t>(c));
    }
}

TEST(PlyExport, WritesOneFloatVertexPerOccupiedVoxel) {
    const ScratchDir dir("ply_float");
    const core::VoxelMap map = MakeExportTestMap();
    WritePly(map, dir / "map.ply");
    EXPECT_EQ(dir.EntryCount(), 1);
    const PlyFile ply = ReadPly(dir / "map.ply");
    ASSERT_FALSE(ply.header.empty());
    EXPECT_EQ(ply.header.front(), "ply");
    EXPECT_TRUE(HasLine(ply, "format binary_little_endian 1.0"));
    for (const char* p :
         {"property float x", "property float y", "property float z", "property uchar red",
          "property uchar green", "property uchar blue", "property uchar label"}) {
        EXPECT_TRUE(HasLine(ply, p)) << p;
    }
    EXPECT_EQ(ply.header.back(), "end_header");
    EXPECT_EQ(VertexCount(ply), OccupiedVoxels(map));
    ExpectVerticesMatchMap<float>(ply, map);
}

TEST(PlyExport, GeoreferencedMapsGetDoubleWorldCoordinates) {
    const ScratchDir dir("ply_double");
    const core::VoxelMap map = MakeExportTestMap(Eigen::Vector3d(512345.25, 5412345.5, 231.0));
    WritePly(map, dir / "map.ply");
    const PlyFile ply = ReadPly(dir / "map.ply");
    EXPECT_TRUE(HasLine(ply, "property double x"));
    EXPECT_TRUE(HasLine(ply, "property double z"));
    EXPECT_EQ(VertexCount(ply), OccupiedVoxels(map));
    ExpectVerticesMatchMap<double>(ply, map);
}

TEST(PlyExport, EmptyMapWritesAValidEmptyCloud) {
    const ScratchDir dir("ply_empty");
    WritePly(core::VoxelMap::Create(kVoxelSize), dir / "empty.ply");
    const PlyFile ply = ReadPly(dir / "empty.ply");
    EXPECT_TRUE(HasLine(ply, "element vertex 0"));
    EXPECT_TRUE(ply.body.empty());
}

TEST(PlyExport, UninitialisedMapIsRejected) {
    const ScratchDir dir("ply_uninitialised");
    EXPECT_THROW(WritePly(core::VoxelMap{}, dir / "map.ply"), InvalidArgumentError);
    EXPECT_EQ(dir.EntryCount(), 0);
}

TEST(PlyExport, MissingDirectoryThrowsNamingThePath) {
    const ScratchDir dir("ply_missing");
    const fs::path path = dir / "missing/map.ply";
    ExpectErrorNaming(path, [&] { WritePly(MakeExportTestMap(), path); });
    EXPECT_EQ(dir.EntryCount(), 0);
}

}  // namespace
}  // namespace strata::io
