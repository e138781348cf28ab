#include "Alignment.hpp"

#include <iomanip>

namespace strata::tools {

void AddAlignOptions(CLI::App& cmd, AlignArgs& args, bool ranges) {
    cmd.add_option("--init", args.init,
                   "Initial guess x,y,z,yaw_deg of the source frame in the map frame")
        ->expected(4)
        ->delimiter(',');
    cmd.add_option("--min-overlap", args.config.min_overlap,
                   "Refuse below this fraction of matched source points")
        ->capture_default_str();
    cmd.add_option("--max-rmse", args.config.max_rmse_m, "Refuse above this residual (m)")
        ->capture_default_str();
    if (ranges) {
        cmd.add_option("--min-range", args.min_range_m, "Drop points closer to their sensor (m)")
            ->capture_default_str();
        cmd.add_option("--max-range", args.max_range_m, "Drop points farther from their sensor (m)")
            ->capture_default_str();
    }
    cmd.add_option("--margin", args.margin_m, "Map read around the guessed source (m)")
        ->capture_default_str();
}

pipeline::AlignRequest AlignRequestOf(const AlignArgs& args) {
    return {args, pipeline::GuessFromXyzYaw(args.init)};
}

void PrintAlignment(const pipeline::MapAlignment& a, std::ostream& out) {
    const registration::RegistrationResult& r = a.result;
    const Eigen::Vector3d t = r.T_map_source.translation();
    out << std::fixed << std::setprecision(3);
    out << (r.converged ? "aligned" : "refused") << ": x " << t.x() << " y " << t.y() << " z "
        << t.z() << " m, yaw " << registration::YawDeg(r.T_map_source) << " deg; rmse " << r.rmse_m
        << " m, overlap " << r.overlap << ", " << r.iterations << " iterations, "
        << std::setprecision(1) << r.time_ms << " ms (" << a.total_ms << " ms with " << a.map_points
        << " map voxels)\n";
    if (!r.converged) out << "reason: " << r.refusal << "\n";
    out << "T (source -> map):\n" << std::setprecision(6);
    for (int row = 0; row < 4; ++row) {
        for (int col = 0; col < 4; ++col) {
            out << (col ? " " : "  ") << std::setw(11) << r.T_map_source.matrix()(row, col);
        }
        out << "\n";
    }
}

}  // namespace strata::tools
