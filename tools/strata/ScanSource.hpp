#pragma once
// Scans to integrate, from a KITTI sequence or from point-cloud files with an optional pose file.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "strata/core/Scan.hpp"
#include "strata/integration/IntegrationConfig.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/io/PointCloudReaders.hpp"
#include "strata/store/SessionWriter.hpp"

namespace CLI {
class App;
}

namespace strata::tools {

/// Adds --bin-fields to a command that reads --scans: float32 values per point of raw .bin scans.
void AddBinFieldsOption(CLI::App& cmd, int& bin_fields);

class ScanSource {
public:
    /// KITTI sequence; `frames` is "A:B" (half-open, either side may be empty) or empty for all.
    static ScanSource Kitti(const std::filesystem::path& dir, const std::string& frames);
    /// Point-cloud files; poses by index from `poses` (KITTI or TUM), identity when empty.
    static ScanSource Files(std::vector<std::filesystem::path> files,
                            const std::filesystem::path& poses, const io::ReadOptions& options);

    [[nodiscard]] size_t size() const { return indices_.size(); }
    [[nodiscard]] core::Scan Read(size_t i) const;
    [[nodiscard]] std::string Describe() const;

private:
    std::optional<io::KittiSequence> kitti_;
    std::vector<size_t> indices_;  // into the sequence, or into files_
    std::vector<std::filesystem::path> files_;
    std::vector<Eigen::Isometry3d> poses_;
    io::ReadOptions options_;
};

/// Integrates every scan of `source` through `writer` (with a progress bar); does not commit.
void IntegrateScans(store::SessionWriter& writer, const ScanSource& source);

}  // namespace strata::tools
