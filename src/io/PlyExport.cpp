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
        std::vector<char> buffer;
        buffer.reserve(kFlushBytes + 64);
        uint64_t written = 0;
        parts([&](const core::VoxelMap& part) {
            openvdb::Int32Grid::ConstAccessor labels = part.label->getConstAccessor();
            detail::ForEachOccupiedVoxel(*part.occupancy, [&](const openvdb::Coord& ijk, float) {
                const Eigen::Vector3d p = frame.VoxelCenter(ijk) + frame.origin;
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
                ++written;
                if (buffer.size() >= kFlushBytes) {
                    os.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
                    buffer.clear();
                }
            });
        });
        if (written != count) {
            throw InvalidArgumentError("cannot export to '" + path.string() +
                                       "': the map's parts changed between the two passes");
        }
        os.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    });
}

}  // namespace strata::io
