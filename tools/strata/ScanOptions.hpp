#pragma once
// Shared by integrate and register: the options that name the scans to read.

#include <CLI/CLI.hpp>

#include "strata/pipeline/ScanSource.hpp"

namespace strata::tools {

/// Adds --bin-fields to a command that reads --scans: float32 values per point of raw .bin scans.
void AddBinFieldsOption(CLI::App& cmd, int& bin_fields);

/// Adds --bag, --points-topic, --no-deskew, --imu-topic and --no-imu, filling `spec`.
void AddRecordingOptions(CLI::App& cmd, pipeline::ScanSpec& spec);

/// Adds --kitti, the recording's options (AddRecordingOptions, --fixed-frame, --odom-topic),
/// --frames, --scans, --bin-fields and --poses, filling `spec`.
void AddScanOptions(CLI::App& cmd, pipeline::ScanSpec& spec);

}  // namespace strata::tools
