// The binary tile format the page reads (docs/viewer.md, "Tile format"), written byte by byte in
// little-endian order so it does not depend on the machine's.
#include <cmath>
#include <cstring>
#include <limits>

#include "Cells.hpp"
#include "strata/core/Error.hpp"

namespace strata::view {
namespace {

constexpr char kMagic[4] = {'S', 'T', 'V', '1'};
constexpr size_t kHeaderBytes = 32;

template <typename T>
void Put(std::string& out, T value) {
    static_assert(std::is_trivially_copyable_v<T>);
    unsigned char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    // Every machine strata builds on is little-endian (x86-64, aarch64); the format says so too.
    out.append(reinterpret_cast<const char*>(bytes), sizeof(T));
}

template <typename T>
T Get(const std::string& in, size_t& at) {
    if (at + sizeof(T) > in.size()) throw FormatError("tile payload: truncated");
    T value;
    std::memcpy(&value, in.data() + at, sizeof(T));
    at += sizeof(T);
    return value;
}

}  // namespace

std::string EncodeCells(const Cells& cells, double voxel_size_m) {
    openvdb::Coord lo = cells.size() ? cells.cell.front() : openvdb::Coord(0);
    openvdb::Coord hi = lo;
    for (const openvdb::Coord& c : cells.cell) {
        lo.minComponent(c);
        hi.maxComponent(c);
    }
    for (int axis = 0; axis < 3; ++axis) {
        if (int64_t{hi[axis]} - lo[axis] > std::numeric_limits<int16_t>::max()) {
            throw InvalidArgumentError("tile cells span more than 32767 cells on an axis");
        }
    }
    const double cell_m = voxel_size_m * static_cast<double>(1 << cells.lod);
    std::string out;
    out.reserve(kHeaderBytes + cells.size() * 12);
    out.append(kMagic, sizeof(kMagic));
    Put(out, static_cast<uint32_t>(cells.size()));
    Put(out, static_cast<int32_t>(cells.lod));
    Put(out, static_cast<float>(cell_m));
    for (int axis = 0; axis < 3; ++axis) Put(out, static_cast<float>(lo[axis] * cell_m));
    Put(out, uint32_t{0});  // reserved
    for (const openvdb::Coord& c : cells.cell) {
        for (int axis = 0; axis < 3; ++axis) Put(out, static_cast<int16_t>(c[axis] - lo[axis]));
    }
    for (const std::vector<uint8_t>* column :
         {&cells.label, &cells.session, &cells.slant, &cells.flags}) {
        out.append(reinterpret_cast<const char*>(column->data()), column->size());
    }
    for (uint16_t object : cells.object) Put(out, object);
    return out;
}

Cells DecodeCells(const std::string& bytes) {
    if (bytes.size() < kHeaderBytes || std::memcmp(bytes.data(), kMagic, 4) != 0) {
        throw FormatError("tile payload: no STV1 header");
    }
    size_t at = 4;
    const auto count = Get<uint32_t>(bytes, at);
    Cells cells;
    cells.lod = Get<int32_t>(bytes, at);
    const auto cell_m = Get<float>(bytes, at);
    openvdb::Coord origin;
    for (int axis = 0; axis < 3; ++axis) {
        origin[axis] = static_cast<int32_t>(std::lround(Get<float>(bytes, at) / cell_m));
    }
    at = kHeaderBytes;
    if (bytes.size() != kHeaderBytes + size_t{count} * 12) {
        throw FormatError("tile payload: size does not match its count");
    }
    for (uint32_t i = 0; i < count; ++i) {
        openvdb::Coord c;
        for (int axis = 0; axis < 3; ++axis) c[axis] = origin[axis] + Get<int16_t>(bytes, at);
        cells.cell.push_back(c);
    }
    for (std::vector<uint8_t>* column :
         {&cells.label, &cells.session, &cells.slant, &cells.flags}) {
        column->assign(bytes.begin() + static_cast<std::ptrdiff_t>(at),
                       bytes.begin() + static_cast<std::ptrdiff_t>(at + count));
        at += count;
    }
    for (uint32_t i = 0; i < count; ++i) cells.object.push_back(Get<uint16_t>(bytes, at));
    return cells;
}

}  // namespace strata::view
