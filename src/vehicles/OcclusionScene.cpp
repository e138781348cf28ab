#include "OcclusionScene.hpp"

#include <array>
#include <limits>
#include <stdexcept>
#include <utility>

#include "strata/core/Error.hpp"

namespace strata::vehicles::detail {

namespace {

// The six faces of a unit cube: outward neighbour offset and the four corners, counter-clockwise
// seen from outside.
struct Face {
    std::array<int, 3> neighbour;
    std::array<std::array<int, 3>, 4> corners;
};
constexpr std::array<Face, 6> kFaces = {{
    {{-1, 0, 0}, {{{0, 0, 0}, {0, 0, 1}, {0, 1, 1}, {0, 1, 0}}}},
    {{1, 0, 0}, {{{1, 0, 0}, {1, 1, 0}, {1, 1, 1}, {1, 0, 1}}}},
    {{0, -1, 0}, {{{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}}}},
    {{0, 1, 0}, {{{0, 1, 0}, {0, 1, 1}, {1, 1, 1}, {1, 1, 0}}}},
    {{0, 0, -1}, {{{0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}}}},
    {{0, 0, 1}, {{{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}}},
}};

}  // namespace

OcclusionScene::OcclusionScene(const std::vector<openvdb::Coord>& voxels, double voxel_size) {
    openvdb::MaskGrid occupied;
    {
        auto acc = occupied.getAccessor();
        for (const openvdb::Coord& c : voxels) acc.setValueOn(c);
    }
    std::vector<std::array<float, 3>> vertices;
    auto acc = occupied.getConstAccessor();
    for (const openvdb::Coord& c : voxels) {
        for (const Face& f : kFaces) {
            if (acc.isValueOn(c.offsetBy(f.neighbour[0], f.neighbour[1], f.neighbour[2]))) continue;
            for (const auto& k : f.corners) {
                vertices.push_back({static_cast<float>((c.x() + k[0]) * voxel_size),
                                    static_cast<float>((c.y() + k[1]) * voxel_size),
                                    static_cast<float>((c.z() + k[2]) * voxel_size)});
            }
        }
    }
    faces_ = vertices.size() / 4;
    device_ = rtcNewDevice("verbose=0");
    if (device_ == nullptr) {
        throw Error("Embree: cannot create a device (error " +
                    std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    }
    scene_ = rtcNewScene(device_);
    if (scene_ == nullptr) Fail("cannot create a scene");
    if (faces_ > 0) {
        RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_QUAD);
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0,
                                                              RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                              vertices.size()));
        auto* q = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
            geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT4, 4 * sizeof(uint32_t), faces_));
        if (v == nullptr || q == nullptr) {
            rtcReleaseGeometry(geom);
            Fail("cannot allocate geometry buffers for " + std::to_string(faces_) + " faces");
        }
        for (size_t k = 0; k < vertices.size(); ++k) {
            for (int a = 0; a < 3; ++a) v[3 * k + a] = vertices[k][a];
        }
        for (size_t k = 0; k < vertices.size(); ++k) q[k] = static_cast<uint32_t>(k);
        rtcCommitGeometry(geom);
        rtcAttachGeometry(scene_, geom);
        rtcReleaseGeometry(geom);  // the scene holds its own reference
    }
    rtcCommitScene(scene_);
    if (rtcGetDeviceError(device_) != RTC_ERROR_NONE) Fail("cannot build the scene");
}

OcclusionScene::~OcclusionScene() { Release(); }

OcclusionScene::OcclusionScene(OcclusionScene&& other) noexcept
    : device_(std::exchange(other.device_, nullptr)),
      scene_(std::exchange(other.scene_, nullptr)),
      faces_(std::exchange(other.faces_, 0)) {}

OcclusionScene& OcclusionScene::operator=(OcclusionScene&& other) noexcept {
    if (this != &other) {
        Release();
        device_ = std::exchange(other.device_, nullptr);
        scene_ = std::exchange(other.scene_, nullptr);
        faces_ = std::exchange(other.faces_, 0);
    }
    return *this;
}

bool OcclusionScene::Blocked(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                             double stop_short_m) const {
    const Eigen::Vector3d d = to - from;
    const double length = d.norm();
    if (length <= stop_short_m) return false;
    const Eigen::Vector3d dir = d / length;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray{};
    ray.org_x = static_cast<float>(from.x());
    ray.org_y = static_cast<float>(from.y());
    ray.org_z = static_cast<float>(from.z());
    ray.dir_x = static_cast<float>(dir.x());
    ray.dir_y = static_cast<float>(dir.y());
    ray.dir_z = static_cast<float>(dir.z());
    ray.tnear = 0.0F;
    ray.tfar = static_cast<float>(length - stop_short_m);
    ray.mask = std::numeric_limits<unsigned>::max();
    rtcOccluded1(scene_, &context, &ray);
    return ray.tfar < 0.0F;  // Embree sets tfar to -inf on a hit
}

void OcclusionScene::Fail(const std::string& what) {
    const RTCError code = rtcGetDeviceError(device_);
    Release();
    throw Error("Embree: " + what + " (error " + std::to_string(int(code)) + ")");
}

void OcclusionScene::Release() noexcept {
    if (scene_ != nullptr) rtcReleaseScene(scene_);
    if (device_ != nullptr) rtcReleaseDevice(device_);
    scene_ = nullptr;
    device_ = nullptr;
}

}  // namespace strata::vehicles::detail
