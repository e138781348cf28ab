#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

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

}  // namespace

SimulatedScan Simulator::SimulateSweep(const SweepRequest& request,
                                       const SensorModel& sensor) const {
    sensor.Validate();
    const size_t beams = sensor.beams();
    const auto columns = static_cast<size_t>(sensor.columns);
    std::vector<float> cos_el(beams), sin_el(beams);
    for (size_t b = 0; b < beams; ++b) {
        const double e = sensor.elevation_deg[b] * M_PI / 180.0;
        cos_el[b] = static_cast<float>(std::cos(e));
        sin_el[b] = static_cast<float>(std::sin(e));
    }
    const auto max_range = static_cast<float>(sensor.max_range_m);
    const uint64_t key = detail::HashKey(request.seed, request.scan_index, 0x5CA7);
    // Chunks of columns, each with its own small buffer of returns (reused from the allocator's
    // pools: no large buffer to fault in per sweep), concatenated in order afterwards.
    constexpr size_t kChunk = 32;
    std::vector<std::vector<RaySample>> chunks((columns + kChunk - 1) / kChunk);
    // Range: chunks of columns; each task traces all beams of its columns.
    tbb::parallel_for(tbb::blocked_range<size_t>(0, chunks.size()), [&](const auto& chunk_range) {
        for (size_t k = chunk_range.begin(); k != chunk_range.end(); ++k) {
            std::vector<RaySample>& out = chunks[k];
            out.reserve(kChunk * beams);
            for (size_t c = k * kChunk; c < std::min(columns, (k + 1) * kChunk); ++c) {
                const int col = static_cast<int>(c);
                const Eigen::Isometry3d T =
                    request.T_world_sensor_end
                        ? Interpolate(request.T_world_sensor, *request.T_world_sensor_end,
                                      sensor.ColumnTimeS(col) * sensor.rate_hz)
                        : request.T_world_sensor;
                const Eigen::Matrix3f R = T.linear().cast<float>();
                const Eigen::Vector3f origin = T.translation().cast<float>();
                const double az = sensor.ColumnAzimuthRad(col);
                const auto ca = static_cast<float>(std::cos(az));
                const auto sa = static_cast<float>(std::sin(az));
                // Beams of a column leave one origin in similar directions: trace packets of 8.
                Eigen::Vector3f dir_sensor[8], dir[8];
                EmbreeScene::Hit hits[8];
                for (size_t b0 = 0; b0 < beams; b0 += 8) {
                    const size_t count = std::min<size_t>(8, beams - b0);
                    for (size_t i = 0; i < count; ++i) {
                        const size_t b = b0 + i;
                        dir_sensor[i] = Eigen::Vector3f(cos_el[b] * ca, cos_el[b] * sa, sin_el[b]);
                        dir[i] = R * dir_sensor[i];
                    }
                    embree_->Intersect8(origin, dir, static_cast<int>(count), max_range, hits);
                    for (size_t i = 0; i < count; ++i) {
                        const EmbreeScene::Hit& hit = hits[i];
                        if (hit.geometry == RTC_INVALID_GEOMETRY_ID) continue;
                        // Random draws keyed by (seed, scan, ray): independent of threads.
                        const uint64_t h = detail::Mix64(key ^ (c * beams + b0 + i));
                        if (ToUnit(h) < sensor.dropout_probability) continue;
                        // |cos| of the incidence angle (dir is a unit vector, the normal not).
                        const float cos_inc = std::abs(hit.normal.dot(dir[i])) / hit.normal.norm();
                        if (cos_inc < sensor.grazing_cos) continue;
                        const Eigen::Vector2f noise = NormalPair(h);
                        const double range = hit.t + sensor.range_noise_m * noise.x();
                        if (range < sensor.min_range_m || range > sensor.max_range_m) continue;
                        // Lambertian return: albedo times the cosine of the incidence angle.
                        const double intensity = reflectivity_[hit.geometry] * cos_inc +
                                                 sensor.intensity_noise * noise.y();
                        out.push_back({dir_sensor[i] * static_cast<float>(range),
                                       static_cast<float>(std::clamp(intensity, 0.0, 1.0)),
                                       hit.geometry, static_cast<uint16_t>(b0 + i),
                                       static_cast<uint16_t>(c)});
                    }
                }
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
            const uint16_t label = labels_[s.mesh];
            const uint16_t instance = instances_[s.mesh];
            scan.points.push_back(s.point_sensor.cast<double>());
            scan.intensity.push_back(s.intensity);
            scan.labels.push_back(classes_[s.mesh]);
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
