#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "ActorScene.hpp"
#include "EmbreeScene.hpp"
#include "Rng.hpp"
#include "strata/core/Labels.hpp"
#include "strata/sim/Simulator.hpp"

namespace strata::sim {
namespace {

// A return of one ray, before it is spread over the scan's arrays.
struct RaySample {
    Eigen::Vector3f point_sensor;
    float intensity;
    uint32_t mesh;
    uint16_t beam;
    uint16_t column;
};

// Uniform in [0, 1) from the upper 53 bits of a hash.
double ToUnit(uint64_t h) { return static_cast<double>(h >> 11) * 0x1.0p-53; }

// Two independent standard normals from a key (Marsaglia's polar method: no trigonometry;
// single precision is plenty for noise of a few centimetres).
Eigen::Vector2f NormalPair(uint64_t key) {
    for (uint64_t i = 1;; ++i) {
        const uint64_t bits = detail::Mix64(key + i);
        const float u = static_cast<float>(bits >> 40) * 0x1.0p-23F - 1.0F;  // 24 bits each
        const float v = static_cast<float>((bits >> 16) & 0xFFFFFF) * 0x1.0p-23F - 1.0F;
        const float s = u * u + v * v;
        if (s > 0.0F && s < 1.0F) {
            const float f = std::sqrt(-2.0F * std::log(s) / s);
            return {u * f, v * f};
        }
    }
}

// Pose of the sensor a fraction s in [0, 1] of the way through the sweep.
Eigen::Isometry3d Interpolate(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, double s) {
    const Eigen::Quaterniond qa(a.linear()), qb(b.linear());
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = qa.slerp(s, qb).toRotationMatrix();
    T.translation() = (1.0 - s) * a.translation() + s * b.translation();
    return T;
}

// What every column of one sweep shares: the scene and the actors placed at the sweep's time,
// the sensor, its beams' elevations and the key of the sweep's random draws.
struct SweepContext {
    const EmbreeScene& embree;
    const std::vector<float>& reflectivity;  // per mesh
    const EmbreeScene* actors = nullptr;     // none when no actor is present
    std::vector<float> actor_reflectivity;   // per actor
    const SensorModel& sensor;
    std::vector<float> cos_el, sin_el;  // per beam
    uint64_t key;

    SweepContext(const EmbreeScene& embree_scene, const std::vector<float>& mesh_reflectivity,
                 const SensorModel& model, uint64_t sweep_key)
        : embree(embree_scene), reflectivity(mesh_reflectivity), sensor(model), key(sweep_key) {
        for (const double elevation_deg : sensor.elevation_deg) {
            const double e = elevation_deg * M_PI / 180.0;
            cos_el.push_back(static_cast<float>(std::cos(e)));
            sin_el.push_back(static_cast<float>(std::sin(e)));
        }
    }
};

// Pose of the sensor when column `col` fires (interpolated when the request gives an end pose).
Eigen::Isometry3d ColumnPose(const SweepRequest& request, const SensorModel& sensor, int col) {
    if (!request.T_world_sensor_end) return request.T_world_sensor;
    return Interpolate(request.T_world_sensor, *request.T_world_sensor_end,
                       sensor.ColumnTimeS(col) * sensor.rate_hz);
}

// Replaces each static hit (or miss) by an actor's surface nearer along the same ray, its
// geometry numbered after the static meshes (SimulatedScan::mesh).
void TakeNearerActors(const SweepContext& ctx, const Eigen::Vector3f& origin,
                      const Eigen::Vector3f* dir, size_t count, EmbreeScene::Hit* hits) {
    float t_far[8];
    EmbreeScene::Hit nearer[8];
    for (size_t i = 0; i < count; ++i) {
        t_far[i] = hits[i].geometry == RTC_INVALID_GEOMETRY_ID
                       ? static_cast<float>(ctx.sensor.max_range_m)
                       : hits[i].t;
    }
    ctx.actors->Intersect8(origin, dir, static_cast<int>(count), t_far, nearer);
    const auto statics = static_cast<uint32_t>(ctx.reflectivity.size());
    for (size_t i = 0; i < count; ++i) {
        if (nearer[i].geometry == RTC_INVALID_GEOMETRY_ID) continue;
        hits[i] = nearer[i];
        hits[i].geometry += statics;
    }
}

// Traces every beam of column c and appends its returns (dropout, grazing cut, range noise and
// Lambertian intensity applied) to `out`.
void TraceColumn(const SweepContext& ctx, const Eigen::Isometry3d& T, size_t c,
                 std::vector<RaySample>& out) {
    const SensorModel& sensor = ctx.sensor;
    const size_t beams = ctx.cos_el.size();
    const Eigen::Matrix3f R = T.linear().cast<float>();
    const Eigen::Vector3f origin = T.translation().cast<float>();
    const double az = sensor.ColumnAzimuthRad(static_cast<int>(c));
    const auto ca = static_cast<float>(std::cos(az));
    const auto sa = static_cast<float>(std::sin(az));
    // Beams of a column leave one origin in similar directions: trace packets of 8.
    Eigen::Vector3f dir_sensor[8], dir[8];
    EmbreeScene::Hit hits[8];
    for (size_t b0 = 0; b0 < beams; b0 += 8) {
        const size_t count = std::min<size_t>(8, beams - b0);
        for (size_t i = 0; i < count; ++i) {
            const size_t b = b0 + i;
            dir_sensor[i] = Eigen::Vector3f(ctx.cos_el[b] * ca, ctx.cos_el[b] * sa, ctx.sin_el[b]);
            dir[i] = R * dir_sensor[i];
        }
        ctx.embree.Intersect8(origin, dir, static_cast<int>(count),
                              static_cast<float>(sensor.max_range_m), hits);
        if (ctx.actors != nullptr) TakeNearerActors(ctx, origin, dir, count, hits);
        for (size_t i = 0; i < count; ++i) {
            const EmbreeScene::Hit& hit = hits[i];
            if (hit.geometry == RTC_INVALID_GEOMETRY_ID) continue;
            // Random draws keyed by (seed, scan, ray): independent of threads.
            const uint64_t h = detail::Mix64(ctx.key ^ (c * beams + b0 + i));
            if (ToUnit(h) < sensor.dropout_probability) continue;
            // |cos| of the incidence angle (dir is a unit vector, the normal not).
            const float cos_inc = std::abs(hit.normal.dot(dir[i])) / hit.normal.norm();
            if (cos_inc < sensor.grazing_cos) continue;
            const Eigen::Vector2f noise = NormalPair(h);
            const double range = hit.t + sensor.range_noise_m * noise.x();
            if (range < sensor.min_range_m || range > sensor.max_range_m) continue;
            // Lambertian return: albedo times the cosine of the incidence angle.
            const float albedo =
                hit.geometry < ctx.reflectivity.size()
                    ? ctx.reflectivity[hit.geometry]
                    : ctx.actor_reflectivity[hit.geometry - ctx.reflectivity.size()];
            const double intensity = albedo * cos_inc + sensor.intensity_noise * noise.y();
            out.push_back({dir_sensor[i] * static_cast<float>(range),
                           static_cast<float>(std::clamp(intensity, 0.0, 1.0)), hit.geometry,
                           static_cast<uint16_t>(b0 + i), static_cast<uint16_t>(c)});
        }
    }
}

}  // namespace

SimulatedScan Simulator::SimulateSweep(const SweepRequest& request,
                                       const SensorModel& sensor) const {
    sensor.Validate();
    SweepContext ctx(*embree_, reflectivity_, sensor,
                     detail::HashKey(request.seed, request.scan_index, 0x5CA7));
    // docs/simulator.md, "Traffic": the actors stand where they are at the sweep's start.
    const detail::PlacedActors placed =
        detail::PlaceActors(*embree_, actors_, actor_meshes_, request.time_s);
    if (placed.scene) {
        ctx.actors = &*placed.scene;
        for (const ActorSpec& a : actors_) ctx.actor_reflectivity.push_back(a.reflectivity);
    }
    const size_t beams = sensor.beams();
    const auto columns = static_cast<size_t>(sensor.columns);
    // Chunks of columns, each with its own small buffer of returns (reused from the allocator's
    // pools: no large buffer to fault in per sweep), concatenated in order afterwards.
    constexpr size_t kChunk = 32;
    std::vector<std::vector<RaySample>> chunks((columns + kChunk - 1) / kChunk);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, chunks.size()), [&](const auto& chunk_range) {
        for (size_t k = chunk_range.begin(); k != chunk_range.end(); ++k) {
            chunks[k].reserve(kChunk * beams);
            for (size_t c = k * kChunk; c < std::min(columns, (k + 1) * kChunk); ++c) {
                TraceColumn(ctx, ColumnPose(request, sensor, static_cast<int>(c)), c, chunks[k]);
            }
        }
    });
    // Concatenate in firing order (column-major, beams top to bottom).
    SimulatedScan result;
    result.rays = beams * columns;
    core::Scan& scan = result.scan;
    scan.T_world_sensor = request.T_world_sensor;
    scan.time_s = request.time_s;
    scan.source = "simulated scan " + std::to_string(request.scan_index);
    size_t valid = 0;
    for (const auto& chunk : chunks) valid += chunk.size();
    scan.points.reserve(valid);
    scan.intensity.reserve(valid);
    scan.labels.reserve(valid);
    scan.instances.reserve(valid);
    result.raw_labels.reserve(valid);
    result.beam.reserve(valid);
    result.column.reserve(valid);
    result.mesh.reserve(valid);
    for (const auto& chunk : chunks) {
        for (const RaySample& s : chunk) {
            uint16_t label = 0, instance = 0;
            core::SemanticClass semantic_class = core::SemanticClass::kUnknown;
            if (s.mesh < labels_.size()) {
                label = labels_[s.mesh];
                instance = instances_[s.mesh];
                semantic_class = classes_[s.mesh];
            } else {  // an actor: moving or standing at the sweep's time
                const size_t a = s.mesh - labels_.size();
                const size_t moving = placed.moving[a];
                label = actor_labels_[a][moving];
                instance = static_cast<uint16_t>(actors_[a].id);
                semantic_class = actor_classes_[a][moving];
            }
            scan.points.push_back(s.point_sensor.cast<double>());
            scan.intensity.push_back(s.intensity);
            scan.labels.push_back(semantic_class);
            scan.instances.push_back(instance);
            result.raw_labels.push_back(uint32_t(label) | (uint32_t(instance) << 16));
            result.beam.push_back(s.beam);
            result.column.push_back(s.column);
            result.mesh.push_back(s.mesh);
        }
    }
    return result;
}

}  // namespace strata::sim
