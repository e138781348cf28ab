#include "strata/io/PcdExport.hpp"

#include <cstdint>
#include <functional>
#include <sstream>
#include <string>

#include "ExportInput.hpp"
#include "strata/core/Error.hpp"
#include "strata/io/AtomicFile.hpp"

namespace strata::io {
namespace {

std::string PcdHeaderText(size_t count, bool use_double, const std::string& what) {
    const int size = use_double ? 8 : 4;
    std::ostringstream h;
    h << "# .PCD v0.7 - Point Cloud Data file format\n";
    std::istringstream lines(what);
    for (std::string line; std::getline(lines, line);) h << "# " << line << "\n";
    h << "VERSION 0.7\nFIELDS x y z intensity\n"
      << "SIZE " << size << ' ' << size << ' ' << size << " 4\n"
      << "TYPE F F F F\nCOUNT 1 1 1 1\n"
      << "WIDTH " << count << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
      << "POINTS " << count << "\nDATA binary\n";
    return h.str();
}

using PointSink = std::function<void(const Eigen::Vector3d&, float)>;

// Writes the `count` points `emit` gives (world frame, intensity) as binary PCD.
void WriteStream(size_t count, bool use_double, const std::string& what,
                 const std::filesystem::path& path,
                 const std::function<void(const PointSink&)>& emit) {
    WriteFileAtomically(path, [&](std::ostream& os) {
        os << PcdHeaderText(count, use_double, what);
        detail::RecordWriter out(os, count, path);
        emit([&](const Eigen::Vector3d& p, float intensity) {
            out.Position(p, use_double);
            out.Value<float>(intensity);
            out.Next();
        });
        out.Finish();
    });
}

}  // namespace

void WritePcd(const PcdPoints& cloud, const std::string& what, const std::filesystem::path& path) {
    if (cloud.intensity.size() != cloud.points.size()) {
        throw InvalidArgumentError("cannot export to '" + path.string() +
                                   "': " + std::to_string(cloud.points.size()) + " points but " +
                                   std::to_string(cloud.intensity.size()) + " intensities");
    }
    WriteStream(cloud.points.size(), !cloud.origin_is_zero, what, path, [&](const PointSink& sink) {
        for (size_t i = 0; i < cloud.points.size(); ++i) {
            sink(cloud.points[i], cloud.intensity[i]);
        }
    });
}

void WritePcd(const core::VoxelMap& frame, const MapParts& parts,
              const std::filesystem::path& path) {
    detail::RequireGrids(frame, path);
    size_t count = 0;
    parts([&](const core::VoxelMap& part) {
        detail::RequireGrids(part, path);
        detail::ForEachOccupiedVoxel(*part.occupancy,
                                     [&](const openvdb::Coord&, float) { ++count; });
    });
    std::ostringstream what;
    what << "strata occupied voxel centres, voxel size " << frame.voxel_size
         << " m; intensity = class (0 unknown ... " << core::kNumClasses - 1 << ")";
    // Two passes (count, then write) with one part in memory at a time, as WritePly.
    WriteStream(count, !frame.origin.isZero(), what.str(), path, [&](const PointSink& sink) {
        parts([&](const core::VoxelMap& part) {
            const openvdb::Int32Grid::ConstAccessor labels = part.label->getConstAccessor();
            detail::ForEachOccupiedVoxel(*part.occupancy, [&](const openvdb::Coord& ijk, float) {
                sink(frame.VoxelCenter(ijk) + frame.origin,
                     static_cast<float>(detail::ClassOf(labels.getValue(ijk))));
            });
        });
    });
}

}  // namespace strata::io
