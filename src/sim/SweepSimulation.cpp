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

// What one ray produced; compacted into the scan in (column, beam) order afterwards.
struct RaySample {
    Eigen::Vector3f point_sensor;
    float intensity;
    uint32_t mesh;  // kNoReturn when the ray produced no point
};
constexpr uint32_t kNoReturn = 0xFFFFFFFFU;

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
    std::vector<RaySample> samples(beams * columns);
    const auto max_range = static_cast<float>(sensor.max_range_m);
    const uint64_t key = detail::HashKey(request.seed, request.scan_index, 0x5CA7);
    // Range: columns; each task traces all beams of its columns.
    tbb::parallel_for(tbb::blocked_range<size_t>(0, columns, 16), [&](const auto& cols) {
        for (size_t c = cols.begin(); c != cols.end(); ++c) {
            const int col = static_cast<int>(c);
            const Eigen::Isometry3d T =
                request.T_world_sensor_end
                    ? Interpolate(request.T_world_sensor, *request.T_world_sensor_end,
                                  sensor.ColumnTimeS(col) * sensor.rate_hz)
                    : request.T_world_sensor;
            const Eigen::Matrix3f R = T.linear().cast<float>();
            const Eigen::Vector3f origin = T.translation().cast<float>();
            const double az = sensor.ColumnAzimuthRad(col);
            const auto ca = static_cast<float>(std::cos(az)), sa = static_cast<float>(std::sin(az));
            // Beams of a column leave one origin in similar directions: trace them as packets.
            Eigen::Vector3f dir_sensor[8], dir[8];
            EmbreeScene::Hit hits[8];
            for (size_t b = 0; b < beams; ++b) {
                const size_t lane = b % 8;
                if (lane == 0) {
                    const int count = static_cast<int>(std::min<size_t>(8, beams - b));
                    for (int i = 0; i < count; ++i) {
                        const size_t bi = b + static_cast<size_t>(i);
                        dir_sensor[i] =
                            Eigen::Vector3f(cos_el[bi] * ca, cos_el[bi] * sa, sin_el[bi]);
                        dir[i] = R * dir_sensor[i];
                    }
                    embree_->Intersect8(origin, dir, count, max_range, hits);
                }
                RaySample& out = samples[c * beams + b];
                out.mesh = kNoReturn;
                const EmbreeScene::Hit& hit = hits[lane];
                if (hit.geometry == RTC_INVALID_GEOMETRY_ID) continue;
                // Random draws keyed by (seed, scan, ray): independent of threads and order.
                const uint64_t h = detail::Mix64(key ^ (c * beams + b));
                if (ToUnit(h) < sensor.dropout_probability) continue;
                // |cos| of the incidence angle; dir is a unit vector, the geometric normal is not.
                const float cos_inc = std::abs(hit.normal.dot(dir[lane])) / hit.normal.norm();
                if (cos_inc < sensor.grazing_cos) continue;
                const Eigen::Vector2f noise = NormalPair(h);
                const double range = hit.t + sensor.range_noise_m * noise.x();
                if (range < sensor.min_range_m || range > sensor.max_range_m) continue;
                // Lambertian return: albedo times the cosine of the incidence angle.
                const double intensity =
                    reflectivity_[hit.geometry] * cos_inc + sensor.intensity_noise * noise.y();
                out.point_sensor = dir_sensor[lane] * static_cast<float>(range);
                out.intensity = static_cast<float>(std::clamp(intensity, 0.0, 1.0));
                out.mesh = hit.geometry;
            }
        }
    });
    // Compact valid returns in firing order (column-major, beams top to bottom).
    SimulatedScan result;
    result.rays = samples.size();
    core::Scan& scan = result.scan;
    scan.T_world_sensor = request.T_world_sensor;
    scan.time_s = request.time_s;
    scan.source = "simulated scan " + std::to_string(request.scan_index);
    const auto valid = static_cast<size_t>(std::count_if(
        samples.begin(), samples.end(), [](const RaySample& s) { return s.mesh != kNoReturn; }));
    scan.points.reserve(valid);
    scan.intensity.reserve(valid);
    scan.labels.reserve(valid);
    scan.instances.reserve(valid);
    result.raw_labels.reserve(valid);
    result.beam.reserve(valid);
    result.column.reserve(valid);
    result.mesh.reserve(valid);
    for (size_t i = 0; i < samples.size(); ++i) {
        const RaySample& s = samples[i];
        if (s.mesh == kNoReturn) continue;
        const uint16_t label = labels_[s.mesh];
        const uint16_t instance = instances_[s.mesh];
        scan.points.push_back(s.point_sensor.cast<double>());
        scan.intensity.push_back(s.intensity);
        scan.labels.push_back(classes_[s.mesh]);
        scan.instances.push_back(instance);
        result.raw_labels.push_back(uint32_t(label) | (uint32_t(instance) << 16));
        result.beam.push_back(static_cast<uint16_t>(i % beams));
        result.column.push_back(static_cast<uint16_t>(i / beams));
        result.mesh.push_back(s.mesh);
    }
    return result;
}

}  // namespace strata::sim
