#include "VehiclesExchange.hpp"

#include <cstddef>
#include <cstdint>

#include "strata/core/Bytes.hpp"
#include "strata/core/Error.hpp"

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

struct FlatSample {
    double xy[2], z_mean, h;
    int32_t x, y, z, unused;
};
struct FlatPart {
    FlatKey key;
    int32_t source;
    double footprint[5], seen[5], base, top, z_min, z_max;
    uint64_t voxels;  // of the vehicle; its coordinates follow in one list
};

}  // namespace

std::string EncodeSamples(const std::vector<vehicles::ObjectSample>& samples) {
    std::vector<FlatSample> flat;
    flat.reserve(samples.size());
    for (const vehicles::ObjectSample& s : samples) {
        FlatSample f{};
        f.xy[0] = s.xy.x(), f.xy[1] = s.xy.y(), f.z_mean = s.z, f.h = s.h;
        f.x = s.voxel.x(), f.y = s.voxel.y(), f.z = s.voxel.z();
        flat.push_back(f);
    }
    std::string out;
    core::PutVector(out, flat);
    return out;
}

std::vector<vehicles::ObjectSample> DecodeSamples(const std::string& bytes) {
    core::ByteReader in(bytes, "vehicles' long objects");
    std::vector<vehicles::ObjectSample> samples;
    for (const FlatSample& f : in.GetVector<FlatSample>()) {
        samples.push_back({Coord(f.x, f.y, f.z), {f.xy[0], f.xy[1]}, f.z_mean, f.h});
    }
    return samples;
}

std::string EncodeLongObjects(const vehicles::LongObjects& long_objects) {
    std::vector<FlatPart> parts;
    std::vector<Coord> voxels;
    for (const vehicles::LongCar& car : long_objects.cars) {
        const vehicles::FittedPart& p = car.part;
        const vehicles::Vehicle& v = p.object.vehicle;
        FlatPart f{};
        f.key = Flat(car.key);
        f.source = static_cast<int32_t>(v.source);
        PutRect(v.footprint, f.footprint);
        PutRect(v.seen, f.seen);
        f.base = p.base, f.top = p.top, f.z_min = p.z_min, f.z_max = p.z_max;
        f.voxels = v.voxels;
        parts.push_back(f);
        voxels.insert(voxels.end(), p.object.voxels.begin(), p.object.voxels.end());
    }
    std::string out;
    core::Put(out, static_cast<uint64_t>(long_objects.objects));
    core::PutVector(out, parts);
    core::PutVector(out, voxels);
    return out;
}

vehicles::LongObjects DecodeLongObjects(const std::string& bytes) {
    core::ByteReader in(bytes, "vehicles' long objects");
    vehicles::LongObjects out;
    out.objects = in.Get<uint64_t>();
    const std::vector<FlatPart> parts = in.GetVector<FlatPart>();
    const std::vector<Coord> voxels = in.GetVector<Coord>();
    size_t next = 0;
    for (const FlatPart& f : parts) {
        if (f.voxels > voxels.size() - next) {
            throw FormatError("vehicles' long objects: more voxels named than sent");
        }
        vehicles::FittedPart p;
        vehicles::Vehicle& v = p.object.vehicle;
        v.source = static_cast<vehicles::VehicleSource>(f.source);
        v.footprint = GetRect(f.footprint), v.seen = GetRect(f.seen);
        v.voxels = f.voxels;
        p.base = f.base, p.top = f.top, p.z_min = f.z_min, p.z_max = f.z_max;
        p.object.voxels.assign(voxels.begin() + static_cast<std::ptrdiff_t>(next),
                               voxels.begin() + static_cast<std::ptrdiff_t>(next + f.voxels));
        next += f.voxels;
        out.cars.push_back({Unflat(f.key), std::move(p)});
    }
    return out;
}

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
