#include "ScanOptions.hpp"

namespace strata::tools {

void AddBinFieldsOption(CLI::App& cmd, int& bin_fields) {
    cmd.add_option("--bin-fields", bin_fields,
                   "float32 values per point of .bin scans: 4 (KITTI: x y z intensity) or 5 "
                   "(nuScenes: x y z intensity ring); default: 5 for *.pcd.bin, else the one "
                   "that divides the file size")
        ->check(CLI::IsMember({4, 5}));
}

void AddScanOptions(CLI::App& cmd, pipeline::ScanSpec& spec) {
    cmd.add_option("--kitti", spec.kitti, "KITTI/SemanticKITTI sequence folder");
    cmd.add_option("--frames", spec.frames, "Frame range A:B of the sequence (half-open)");
    cmd.add_option("--scans", spec.files, "PCD, PLY, LAS, .bin or text files (.bz2 allowed)");
    AddBinFieldsOption(cmd, spec.bin_fields);
    cmd.add_option("--poses", spec.poses, "Pose file for --scans (KITTI 3x4 or TUM), by index");
}

}  // namespace strata::tools
