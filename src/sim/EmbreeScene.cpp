#include "EmbreeScene.hpp"

#include <algorithm>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "strata/core/Error.hpp"

namespace strata::sim {
namespace {

[[noreturn]] void ThrowEmbree(RTCError code, const std::string& what) {
    throw Error("Embree: " + what + " (error " + std::to_string(int(code)) + ")");
}

// Closest point of triangle abc to p, by the Voronoi region of p (vertex, edge or face).
Eigen::Vector3f ClosestOnTriangle(const Eigen::Vector3f& p, const Eigen::Vector3f& a,
                                  const Eigen::Vector3f& b, const Eigen::Vector3f& c) {
    const Eigen::Vector3f ab = b - a, ac = c - a, ap = p - a;
    const float d1 = ab.dot(ap), d2 = ac.dot(ap);
    if (d1 <= 0 && d2 <= 0) return a;
    const Eigen::Vector3f bp = p - b;
    const float d3 = ab.dot(bp), d4 = ac.dot(bp);
    if (d3 >= 0 && d4 <= d3) return b;
    const float vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
    const Eigen::Vector3f cp = p - c;
    const float d5 = ab.dot(cp), d6 = ac.dot(cp);
    if (d6 >= 0 && d5 <= d6) return c;
    const float vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
    const float va = d3 * d6 - d5 * d4;
    if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
        return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
    }
    const float denom = 1.0F / (va + vb + vc);
    return a + ab * (vb * denom) + ac * (vc * denom);
}

// Point-query callback: shrinks the search radius to the closest triangle seen so far.
bool ClosestTriangle(RTCPointQueryFunctionArguments* args) {
    auto* scene = static_cast<RTCScene>(args->userPtr);
    RTCGeometry geom = rtcGetGeometry(scene, args->geomID);
    const auto* v =
        static_cast<const float*>(rtcGetGeometryBufferData(geom, RTC_BUFFER_TYPE_VERTEX, 0));
    const auto* t =
        static_cast<const uint32_t*>(rtcGetGeometryBufferData(geom, RTC_BUFFER_TYPE_INDEX, 0));
    const uint32_t* tri = t + 3 * args->primID;
    auto vertex = [&](uint32_t k) { return Eigen::Vector3f(v[3 * k], v[3 * k + 1], v[3 * k + 2]); };
    const Eigen::Vector3f p(args->query->x, args->query->y, args->query->z);
    const float d =
        (ClosestOnTriangle(p, vertex(tri[0]), vertex(tri[1]), vertex(tri[2])) - p).norm();
    if (d >= args->query->radius) return false;
    args->query->radius = d;
    return true;
}

}  // namespace

float EmbreeScene::ClosestDistance(const Eigen::Vector3f& point, float max_radius) const {
    RTCPointQuery query{};
    query.x = point.x(), query.y = point.y(), query.z = point.z();
    query.radius = max_radius;
    query.time = 0.0F;
    RTCPointQueryContext context;
    rtcInitPointQueryContext(&context);
    rtcPointQuery(scene_, &query, &context, ClosestTriangle, scene_);
    return query.radius < max_radius ? query.radius : std::numeric_limits<float>::infinity();
}

EmbreeScene::EmbreeScene(const std::vector<Mesh>& meshes) {
    device_ = rtcNewDevice("verbose=0");
    if (device_ == nullptr) ThrowEmbree(rtcGetDeviceError(nullptr), "cannot create a device");
    // Built once and queried many times: spend the build time on a better BVH.
    Build(meshes, RTC_BUILD_QUALITY_HIGH);
}

EmbreeScene::EmbreeScene(const EmbreeScene& device_owner, const std::vector<Mesh>& meshes)
    : device_(device_owner.device_) {
    rtcRetainDevice(device_);
    // Built for one sweep of rays over a few thousand triangles: the build time counts.
    Build(meshes, RTC_BUILD_QUALITY_LOW);
}

void EmbreeScene::Build(const std::vector<Mesh>& meshes, RTCBuildQuality quality) {
    scene_ = rtcNewScene(device_);
    if (scene_ == nullptr) {
        Fail("cannot create a scene");
    }
    rtcSetSceneBuildQuality(scene_, quality);
    for (size_t i = 0; i < meshes.size(); ++i) {
        const Mesh& m = meshes[i];
        if (m.triangles.empty()) continue;
        RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0,
                                                              RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                              m.vertices.size()));
        auto* t = static_cast<uint32_t*>(
            rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                    3 * sizeof(uint32_t), m.triangles.size()));
        if (v == nullptr || t == nullptr) {
            rtcReleaseGeometry(geom);
            Fail("cannot allocate geometry buffers");
        }
        for (size_t k = 0; k < m.vertices.size(); ++k) {
            std::memcpy(v + 3 * k, m.vertices[k].data(), 3 * sizeof(float));
        }
        std::memcpy(t, m.triangles.data(), m.triangles.size() * 3 * sizeof(uint32_t));
        rtcSetGeometryBuildQuality(geom, quality);
        rtcCommitGeometry(geom);
        rtcAttachGeometryByID(scene_, geom, static_cast<unsigned>(i));
        rtcReleaseGeometry(geom);  // the scene holds its own reference
    }
    rtcCommitScene(scene_);
    if (rtcGetDeviceError(device_) != RTC_ERROR_NONE) Fail("cannot build the scene");
}

EmbreeScene::~EmbreeScene() { Release(); }

EmbreeScene::EmbreeScene(EmbreeScene&& other) noexcept
    : device_(std::exchange(other.device_, nullptr)),
      scene_(std::exchange(other.scene_, nullptr)) {}

EmbreeScene& EmbreeScene::operator=(EmbreeScene&& other) noexcept {
    if (this != &other) {
        Release();
        device_ = std::exchange(other.device_, nullptr);
        scene_ = std::exchange(other.scene_, nullptr);
    }
    return *this;
}

void EmbreeScene::Fail(const std::string& what) {
    const RTCError code = rtcGetDeviceError(device_);
    Release();
    ThrowEmbree(code, what);
}

void EmbreeScene::Release() noexcept {
    if (scene_ != nullptr) rtcReleaseScene(scene_);
    if (device_ != nullptr) rtcReleaseDevice(device_);
    scene_ = nullptr;
    device_ = nullptr;
}

bool EmbreeScene::Intersect(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction,
                            float t_near, float t_far, Hit& hit) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh;
    rh.ray.org_x = origin.x();
    rh.ray.org_y = origin.y();
    rh.ray.org_z = origin.z();
    rh.ray.dir_x = direction.x();
    rh.ray.dir_y = direction.y();
    rh.ray.dir_z = direction.z();
    rh.ray.tnear = t_near;
    rh.ray.tfar = t_far;
    rh.ray.time = 0.0F;
    rh.ray.mask = 0xFFFFFFFFU;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    hit.t = rh.ray.tfar;
    hit.normal = Eigen::Vector3f(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
    hit.geometry = rh.hit.geomID;
    return true;
}

void EmbreeScene::Intersect8(const Eigen::Vector3f& origin, const Eigen::Vector3f* direction,
                             int count, float t_far, Hit* hits) const {
    float far[8];
    std::fill(far, far + 8, t_far);
    Intersect8(origin, direction, count, far, hits);
}

void EmbreeScene::Intersect8(const Eigen::Vector3f& origin, const Eigen::Vector3f* direction,
                             int count, const float* t_far, Hit* hits) const {
    alignas(32) int valid[8];
    alignas(32) RTCRayHit8 rh;
    for (int i = 0; i < 8; ++i) {
        const bool on = i < count;
        valid[i] = on ? -1 : 0;
        const Eigen::Vector3f d = on ? direction[i] : Eigen::Vector3f::UnitX();
        rh.ray.org_x[i] = origin.x();
        rh.ray.org_y[i] = origin.y();
        rh.ray.org_z[i] = origin.z();
        rh.ray.dir_x[i] = d.x();
        rh.ray.dir_y[i] = d.y();
        rh.ray.dir_z[i] = d.z();
        rh.ray.tnear[i] = 0.0F;
        rh.ray.tfar[i] = t_far[on ? i : 0];  // an unused lane is masked off anyway
        rh.ray.time[i] = 0.0F;
        rh.ray.mask[i] = 0xFFFFFFFFU;
        rh.ray.id[i] = static_cast<unsigned>(i);
        rh.ray.flags[i] = 0;
        rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    rtcIntersect8(valid, scene_, &context, &rh);
    for (int i = 0; i < count; ++i) {
        hits[i].geometry = rh.hit.geomID[i];
        hits[i].t = rh.ray.tfar[i];
        hits[i].normal = Eigen::Vector3f(rh.hit.Ng_x[i], rh.hit.Ng_y[i], rh.hit.Ng_z[i]);
    }
}

}  // namespace strata::sim
