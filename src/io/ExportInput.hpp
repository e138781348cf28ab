#pragma once

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <ostream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "strata/core/Error.hpp"
#include "strata/core/GridTypes.hpp"
#include "strata/core/Labels.hpp"
#include "strata/core/VoxelMap.hpp"

// What every exporter reads from a map: the checked grids, the class of a label value, and the
// observed voxels with active tiles expanded (a pruned map stores uniform free space as tiles).
namespace strata::io::detail {

/// @brief Throws InvalidArgumentError unless the map has all grids and a voxel size.
/// @param target what is being exported, for the message ("'out/map.ply'").
inline void RequireGrids(const core::VoxelMap& map, const std::string& target) {
    if (!map.occupancy || !map.label || !map.label_weight || !map.endpoints ||
        !(map.voxel_size > 0.0)) {
        throw InvalidArgumentError("cannot export " + target +
                                   ": the map is not initialised (use VoxelMap::Create)");
    }
}
inline void RequireGrids(const core::VoxelMap& map, const std::filesystem::path& path) {
    RequireGrids(map, "to '" + path.string() + "'");
}

/// @brief The class of a `label` grid value; values outside the taxonomy are kUnknown.
[[nodiscard]] inline core::SemanticClass ClassOf(int32_t label) {
    return label >= 0 && label < core::kNumClasses ? static_cast<core::SemanticClass>(label)
                                                   : core::SemanticClass::kUnknown;
}

/// @brief Calls fn(ijk, log_odds) for every active occupancy voxel, in tree order, expanding
/// active tiles voxel by voxel. Sequential.
template <typename Fn>
void ForEachObservedVoxel(const openvdb::FloatGrid& occupancy, Fn&& fn) {
    for (auto iter = occupancy.cbeginValueOn(); iter; ++iter) {
        if (iter.isVoxelValue()) {
            fn(iter.getCoord(), *iter);
            continue;
        }
        openvdb::CoordBBox bbox;
        iter.getBoundingBox(bbox);
        for (auto ijk = bbox.begin(); ijk; ++ijk) fn(*ijk, *iter);
    }
}

/// @brief Calls fn(ijk, log_odds) for every occupied voxel (log-odds > 0), in tree order,
/// expanding occupied tiles; free tiles are skipped without being walked. Sequential.
template <typename Fn>
void ForEachOccupiedVoxel(const openvdb::FloatGrid& occupancy, Fn&& fn) {
    for (auto iter = occupancy.cbeginValueOn(); iter; ++iter) {
        if (!(*iter > 0.0f)) continue;
        openvdb::CoordBBox bbox;
        iter.getBoundingBox(bbox);
        for (auto ijk = bbox.begin(); ijk; ++ijk) fn(*ijk, *iter);
    }
}

/// @brief The binary records of a point file (PLY, PCD) after its header: buffered, written in
/// blocks of about 1 MB, and counted against the count the header announced, for exporters that
/// count in a first pass over a map's parts and write in a second.
class RecordWriter {
public:
    RecordWriter(std::ostream& os, uint64_t count, std::filesystem::path path)
        : os_(os), count_(count), path_(std::move(path)) {
        buffer_.reserve(kFlushBytes + 64);
    }

    /// The little-endian bytes of a float or double, whatever the host byte order.
    template <typename T>
    void Value(T value) {
        using UInt = std::conditional_t<sizeof(T) == 8, uint64_t, uint32_t>;
        static_assert(sizeof(T) == sizeof(UInt));
        UInt bits = 0;
        std::memcpy(&bits, &value, sizeof(T));
        for (size_t i = 0; i < sizeof(T); ++i) {
            buffer_.push_back(static_cast<char>((bits >> (8 * i)) & 0xFF));
        }
    }
    /// x y z as float, or as double when float32 would lose the world frame (a map origin).
    void Position(const Eigen::Vector3d& p, bool use_double) {
        for (int axis = 0; axis < 3; ++axis) {
            use_double ? Value<double>(p[axis]) : Value<float>(static_cast<float>(p[axis]));
        }
    }
    void Byte(uint8_t byte) { buffer_.push_back(static_cast<char>(byte)); }
    /// Ends one record.
    void Next() {
        ++written_;
        if (buffer_.size() >= kFlushBytes) Flush();
    }
    /// Writes what is left; throws InvalidArgumentError naming the file when the records were
    /// not the count announced (a map's parts changed between the passes).
    void Finish() {
        if (written_ != count_) {
            throw InvalidArgumentError("cannot export to '" + path_.string() +
                                       "': the map's parts changed between the two passes");
        }
        Flush();
    }

private:
    static constexpr size_t kFlushBytes = size_t{1} << 20;
    void Flush() {
        os_.write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
        buffer_.clear();
    }
    std::ostream& os_;
    uint64_t count_ = 0, written_ = 0;
    std::filesystem::path path_;
    std::vector<char> buffer_;
};

}  // namespace strata::io::detail
