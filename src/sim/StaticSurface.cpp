#include "strata/sim/StaticSurface.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>

#include "NearestOrigins.hpp"
#include "Rng.hpp"
#include "strata/core/Error.hpp"
#include "strata/sim/Simulator.hpp"

namespace strata::sim {
namespace {

// A point hidden from its nearest scan positions is taken as unobserved (bounds the cost where
// most of the surface is hidden, as indoors).
constexpr size_t kOriginsTried = 8;
// Buckets of scan positions for the nearest-origin search (any size gives the same answer).
constexpr double kOriginCellM = 20.0;

}  // namespace

SurfaceSample SampleStaticSurface(const Scene& scene, double spacing_m, uint64_t seed) {
    if (!(spacing_m > 0.0)) throw InvalidArgumentError("surface spacing must be positive");
    const double density = 1.0 / (spacing_m * spacing_m);
    SurfaceSample sample;
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
        const Mesh& mesh = scene.meshes[m];
        if (!mesh.is_static) continue;
        detail::Rng rng(detail::HashKey(seed, m, 0x5A3F));
        for (const auto& tri : mesh.triangles) {
            const Eigen::Vector3d a = mesh.vertices[tri[0]].cast<double>();
            const Eigen::Vector3d b = mesh.vertices[tri[1]].cast<double>();
            const Eigen::Vector3d c = mesh.vertices[tri[2]].cast<double>();
            // Expected count area * density; the fraction is drawn so the total is unbiased.
            const double expected = 0.5 * (b - a).cross(c - a).norm() * density;
            auto count = static_cast<size_t>(expected);
            if (rng.Uniform() < expected - static_cast<double>(count)) ++count;
            for (size_t k = 0; k < count; ++k) {
                // Uniform point in a triangle (square-root parametrisation).
                const double r1 = std::sqrt(rng.Uniform()), r2 = rng.Uniform();
                sample.points.push_back((1.0 - r1) * a + r1 * (1.0 - r2) * b + r1 * r2 * c);
                sample.labels.push_back(mesh.label);
                sample.instances.push_back(mesh.instance);
            }
        }
    }
    sample.observed.assign(sample.points.size(), 0);
    return sample;
}

void MarkObserved(SurfaceSample& sample, const Simulator& simulator,
                  const std::vector<Eigen::Vector3d>& origins_world, double max_range_m,
                  double min_elevation_deg, double max_elevation_deg) {
    const double sin_min = std::sin(min_elevation_deg * M_PI / 180.0);
    const double sin_max = std::sin(max_elevation_deg * M_PI / 180.0);
    sample.observed.assign(sample.points.size(), 0);
    const detail::NearestOrigins nearest(origins_world, kOriginCellM);
    // Range: points; each point tries its nearest origins and stops at the first that sees it.
    tbb::parallel_for(tbb::blocked_range<size_t>(0, sample.points.size(), 1024),
                      [&](const tbb::blocked_range<size_t>& r) {
                          std::vector<std::pair<double, size_t>> by_distance;
                          for (size_t i = r.begin(); i != r.end(); ++i) {
                              nearest.Find(sample.points[i], kOriginsTried, by_distance);
                              const size_t tries = by_distance.size();
                              for (size_t k = 0; k < tries; ++k) {
                                  const Eigen::Vector3d& o = origins_world[by_distance[k].second];
                                  const Eigen::Vector3d d = sample.points[i] - o;
                                  const double dist = d.norm();
                                  if (dist > max_range_m || dist < 1e-6) break;
                                  const double sin_elevation = d.z() / dist;
                                  if (sin_elevation < sin_min || sin_elevation > sin_max) continue;
                                  // Stop just short of the point: it lies on its own surface.
                                  if (!simulator.CastRay(o, d, dist - 0.02)) {
                                      sample.observed[i] = 1;
                                      break;
                                  }
                              }
                          }
                      });
}

void WriteSurfacePly(const std::filesystem::path& path, const SurfaceSample& sample,
                     const Eigen::Isometry3d& T_out_world) {
    std::ofstream out(path, std::ios::binary);
    out << "ply\nformat binary_little_endian 1.0\n"
        << "comment strata simulator: static surface sample, metres\n"
        << "element vertex " << sample.points.size() << "\n"
        << "property float x\nproperty float y\nproperty float z\n"
        << "property ushort label\nproperty ushort instance\nproperty uchar observed\n"
        << "end_header\n";
    for (size_t i = 0; i < sample.points.size(); ++i) {
        const Eigen::Vector3f p = (T_out_world * sample.points[i]).cast<float>();
        out.write(reinterpret_cast<const char*>(p.data()), 3 * sizeof(float));
        out.write(reinterpret_cast<const char*>(&sample.labels[i]), sizeof(uint16_t));
        out.write(reinterpret_cast<const char*>(&sample.instances[i]), sizeof(uint16_t));
        out.write(reinterpret_cast<const char*>(&sample.observed[i]), sizeof(uint8_t));
    }
    out.close();
    if (!out) throw IoError("cannot write " + path.string());
}

}  // namespace strata::sim
