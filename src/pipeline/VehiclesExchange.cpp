// What ranks send each other of the vehicles (docs/scale.md): each record with every field it
// has (core/Bytes.hpp names them once for both directions; keys are plain values).
#include "VehiclesExchange.hpp"

#include "strata/core/Bytes.hpp"

namespace strata::core {

template <>
struct Fields<vehicles::OrientedRect> {
    template <typename Io, typename R>
    static void Visit(Io& io, R& r) {
        io(r.center, r.length, r.width, r.yaw_rad);
    }
};

template <>
struct Fields<vehicles::Vehicle> {
    template <typename Io, typename V>
    static void Visit(Io& io, V& v) {
        io(v.id, v.source, v.footprint, v.seen, v.ground_z, v.height, v.voxels, v.cleared_voxels,
           v.refilled_cells, v.refused_cells, v.already_ground_cells, v.ring_cells, v.ground_plane);
    }
};

template <>
struct Fields<vehicles::ObjectSample> {
    template <typename Io, typename S>
    static void Visit(Io& io, S& s) {
        io(s.voxel, s.xy, s.z, s.h);
    }
};

template <>
struct Fields<vehicles::FittedPart> {
    template <typename Io, typename P>
    static void Visit(Io& io, P& p) {
        io(p.object.vehicle, p.object.voxels, p.base, p.top, p.z_min, p.z_max);
    }
};

template <>
struct Fields<vehicles::LongCar> {
    template <typename Io, typename C>
    static void Visit(Io& io, C& c) {
        io(c.key, c.part);
    }
};

template <>
struct Fields<vehicles::LongObjects> {
    template <typename Io, typename L>
    static void Visit(Io& io, L& l) {
        io(l.cars, l.objects);
    }
};

template <>
struct Fields<vehicles::WindowVehicles> {
    template <typename Io, typename W>
    static void Visit(Io& io, W& w) {
        io(w.vehicles, w.cleared, w.refilled, w.candidates, w.occluder_faces, w.long_samples);
    }
};

}  // namespace strata::core

namespace strata::pipeline::detail {

std::string EncodeSamples(const std::vector<vehicles::ObjectSample>& samples) {
    std::string out;
    core::Put(out, samples);
    return out;
}

std::vector<vehicles::ObjectSample> DecodeSamples(const std::string& bytes) {
    core::ByteReader in(bytes, "vehicles' long objects");
    return in.Get<std::vector<vehicles::ObjectSample>>();
}

std::string EncodeLongObjects(const vehicles::LongObjects& long_objects) {
    std::string out;
    core::Put(out, long_objects);
    return out;
}

vehicles::LongObjects DecodeLongObjects(const std::string& bytes) {
    core::ByteReader in(bytes, "vehicles' long objects");
    return in.Get<vehicles::LongObjects>();
}

std::string EncodeWindows(const std::vector<vehicles::WindowVehicles>& found,
                          size_t ground_columns) {
    std::string out;
    core::Put(out, static_cast<uint64_t>(ground_columns));
    core::Put(out, found);
    return out;
}

std::vector<vehicles::WindowVehicles> DecodeWindows(const std::string& bytes,
                                                    size_t& ground_columns) {
    core::ByteReader in(bytes, "vehicles");
    ground_columns += in.Get<uint64_t>();
    return in.Get<std::vector<vehicles::WindowVehicles>>();
}

}  // namespace strata::pipeline::detail
