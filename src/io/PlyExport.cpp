#include "strata/io/PlyExport.hpp"

#include <cstdint>
#include <cstring>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

#include "ExportInput.hpp"
#include "strata/core/Labels.hpp"
#include "strata/io/AtomicFile.hpp"

namespace strata::io {
namespace {

std::string Header(const core::VoxelMap& map, uint64_t count, bool use_double) {
    const char* type = use_double ? "double" : "float";
    std::ostringstream h;
    h << "ply\nformat binary_little_endian 1.0\n"
      << "comment strata occupied voxel centres, voxel size " << map.voxel_size << " m\n"
      << std::setprecision(17)  // the origin exactly, as in the VDB metadata
      << "comment world frame = map frame + origin " << map.origin.x() << ' ' << map.origin.y()
      << ' ' << map.origin.z() << "\n"
      << "comment label:";
    for (int c = 0; c < core::kNumClasses; ++c) {
        h << ' ' << c << '=' << core::ClassName(static_cast<core::SemanticClass>(c));
    }
    h << "\n"
      << "element vertex " << count << "\n"
      << "property " << type << " x\nproperty " << type << " y\nproperty " << type << " z\n"
      << "property uchar red\nproperty uchar green\nproperty uchar blue\n"
      << "property uchar label\nend_header\n";
    return h.str();
}

}  // namespace

void WritePly(const core::VoxelMap& map, const std::filesystem::path& path) {
    WritePly(
        map, [&](const std::function<void(const core::VoxelMap&)>& visit) { visit(map); }, path);
}

void WritePly(const core::VoxelMap& frame, const MapParts& parts,
              const std::filesystem::path& path) {
    detail::RequireGrids(frame, path);
    uint64_t count = 0;
    parts([&](const core::VoxelMap& part) {
        detail::RequireGrids(part, path);
        detail::ForEachOccupiedVoxel(*part.occupancy,
                                     [&](const openvdb::Coord&, float) { ++count; });
    });
    const bool use_double = !frame.origin.isZero();

    WriteFileAtomically(path, [&](std::ostream& os) {
        os << Header(frame, count, use_double);
        detail::RecordWriter out(os, count, path);
        parts([&](const core::VoxelMap& part) {
            openvdb::Int32Grid::ConstAccessor labels = part.label->getConstAccessor();
            detail::ForEachOccupiedVoxel(*part.occupancy, [&](const openvdb::Coord& ijk, float) {
                out.Position(frame.VoxelCenter(ijk) + frame.origin, use_double);
                const core::SemanticClass c = detail::ClassOf(labels.getValue(ijk));
                const core::Rgb rgb = core::ClassColor(c);
                for (uint8_t byte : {rgb.r, rgb.g, rgb.b, static_cast<uint8_t>(c)}) out.Byte(byte);
                out.Next();
            });
        });
        out.Finish();
    });
}

}  // namespace strata::io
