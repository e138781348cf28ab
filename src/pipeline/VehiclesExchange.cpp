#include "VehiclesExchange.hpp"

#include <cstdint>

#include "strata/core/Bytes.hpp"

namespace strata::pipeline::detail {
namespace {

using openvdb::Coord;

struct FlatKey {
    int32_t x, y, z, part;
};
FlatKey Flat(const vehicles::CarKey& k) { return {k.first.x(), k.first.y(), k.first.z(), k.part}; }
vehicles::CarKey Unflat(const FlatKey& k) { return {Coord(k.x, k.y, k.z), k.part}; }
struct FlatVehicle {
    FlatKey key;
    int32_t source;
    double footprint[5], seen[5], ground_z, height, plane[3];
    uint64_t voxels, cleared, refilled, refused, already_ground, ring;
};
struct FlatCleared {
    int32_t x, y, z;
    FlatKey key;
};
struct FlatRefilled {
    int32_t x, y, z;
    float ground_z;
};
void PutRect(const vehicles::OrientedRect& r, double* out) {
    out[0] = r.center.x(), out[1] = r.center.y(), out[2] = r.length, out[3] = r.width;
    out[4] = r.yaw_rad;
}
vehicles::OrientedRect GetRect(const double* in) {
    vehicles::OrientedRect r;
    r.center = {in[0], in[1]}, r.length = in[2], r.width = in[3], r.yaw_rad = in[4];
    return r;
}

}  // namespace

std::string EncodeWindows(const std::vector<vehicles::WindowVehicles>& found,
                          size_t ground_columns) {
    std::vector<FlatVehicle> cars;
    std::vector<FlatCleared> cleared;
    std::vector<FlatRefilled> refilled;
    uint64_t candidates = 0, faces = 0;
    for (const vehicles::WindowVehicles& w : found) {
        for (const auto& [key, v] : w.vehicles) {
            FlatVehicle f{};
            f.key = Flat(key);
            f.source = static_cast<int32_t>(v.source);
            PutRect(v.footprint, f.footprint);
            PutRect(v.seen, f.seen);
            f.ground_z = v.ground_z, f.height = v.height;
            for (int k = 0; k < 3; ++k) f.plane[k] = v.ground_plane[k];
            f.voxels = v.voxels, f.cleared = v.cleared_voxels, f.refilled = v.refilled_cells;
            f.refused = v.refused_cells, f.already_ground = v.already_ground_cells;
            f.ring = v.ring_cells;
            cars.push_back(f);
        }
        for (const auto& [c, key] : w.cleared) cleared.push_back({c.x(), c.y(), c.z(), Flat(key)});
        for (const auto& [c, z] : w.refilled) refilled.push_back({c.x(), c.y(), c.z(), z});
        candidates += w.candidates, faces += w.occluder_faces;
    }
    std::string out;
    core::Put(out, static_cast<uint64_t>(ground_columns));
    core::Put(out, candidates);
    core::Put(out, faces);
    core::PutVector(out, cars);
    core::PutVector(out, cleared);
    core::PutVector(out, refilled);
    return out;
}

vehicles::WindowVehicles DecodeWindows(const std::string& bytes, size_t& ground_columns) {
    core::ByteReader in(bytes, "vehicles");
    vehicles::WindowVehicles w;
    ground_columns += in.Get<uint64_t>();
    w.candidates = in.Get<uint64_t>();
    w.occluder_faces = in.Get<uint64_t>();
    for (const FlatVehicle& f : in.GetVector<FlatVehicle>()) {
        vehicles::Vehicle v;
        v.source = static_cast<vehicles::VehicleSource>(f.source);
        v.footprint = GetRect(f.footprint), v.seen = GetRect(f.seen);
        v.ground_z = f.ground_z, v.height = f.height;
        v.ground_plane = {f.plane[0], f.plane[1], f.plane[2]};
        v.voxels = f.voxels, v.cleared_voxels = f.cleared, v.refilled_cells = f.refilled;
        v.refused_cells = f.refused, v.already_ground_cells = f.already_ground;
        v.ring_cells = f.ring;
        w.vehicles.emplace_back(Unflat(f.key), v);
    }
    for (const FlatCleared& c : in.GetVector<FlatCleared>()) {
        w.cleared.emplace_back(Coord(c.x, c.y, c.z), Unflat(c.key));
    }
    for (const FlatRefilled& r : in.GetVector<FlatRefilled>()) {
        w.refilled.emplace_back(Coord(r.x, r.y, r.z), r.ground_z);
    }
    return w;
}

}  // namespace strata::pipeline::detail
