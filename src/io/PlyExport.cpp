#include "strata/io/PlyExport.hpp"

#include <cstdint>
#include <cstring>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

#include "strata/io/AtomicFile.hpp"
#include "ExportInput.hpp"
#include "strata/core/Labels.hpp"

namespace strata::io {
namespace {

constexpr size_t kFlushBytes = size_t{1} << 20;

// Appends the little-endian bytes of a float or double, whatever the host byte order.
template <typename T, typename UInt>
void AppendLittleEndian(std::vector<char>& out, T value) {
    static_assert(sizeof(T) == sizeof(UInt));
    UInt bits = 0;
    std::memcpy(&bits, &value, sizeof(T));
    for (size_t i = 0; i < sizeof(T); ++i)
        out.push_back(static_cast<char>((bits >> (8 * i)) & 0xFF));
}

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
    detail::RequireGrids(map, path);
    uint64_t count = 0;
    detail::ForEachOccupiedVoxel(*map.occupancy, [&](const openvdb::Coord&, float) { ++count; });
    const bool use_double = !map.origin.isZero();
    openvdb::Int32Grid::ConstAccessor labels = map.label->getConstAccessor();

    WriteFileAtomically(path, [&](std::ostream& os) {
        os << Header(map, count, use_double);
        std::vector<char> buffer;
        buffer.reserve(kFlushBytes + 64);
        detail::ForEachOccupiedVoxel(*map.occupancy, [&](const openvdb::Coord& ijk, float) {
            const Eigen::Vector3d p = map.VoxelCenter(ijk) + map.origin;
            for (int axis = 0; axis < 3; ++axis) {
                if (use_double) {
                    AppendLittleEndian<double, uint64_t>(buffer, p[axis]);
                } else {
                    AppendLittleEndian<float, uint32_t>(buffer, static_cast<float>(p[axis]));
                }
            }
            const core::SemanticClass c = detail::ClassOf(labels.getValue(ijk));
            const core::Rgb rgb = core::ClassColor(c);
            for (uint8_t byte : {rgb.r, rgb.g, rgb.b, static_cast<uint8_t>(c)}) {
                buffer.push_back(static_cast<char>(byte));
            }
            if (buffer.size() >= kFlushBytes) {
                os.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
                buffer.clear();
            }
        });
        os.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    });
}

}  // namespace strata::io
