#pragma once
// Where new scans or a session sit in a stored map (`strata register`; the map is only read),
// and the cloud of a scan source that `register` and `integrate --align` align.

#include <nlohmann/json.hpp>
#include <string>

#include "strata/pipeline/Alignment.hpp"
#include "strata/pipeline/Progress.hpp"
#include "strata/pipeline/ScanSource.hpp"

namespace strata::pipeline {

/// @brief Reads every scan of `source` into the cloud to align. A single scan read `as_is`
/// stays in its own frame (the range limits then apply in AlignToMap); anything else is
/// accumulated in the frame of the scans' poses, thinned, points outside [min_range_m,
/// max_range_m] of their sensor left out. Reports the stage "reading scans".
/// @throw InvalidArgumentError when `source` holds no scan; the readers' errors.
[[nodiscard]] SourceCloud ReadSourceCloud(const ScanSource& source, bool as_is,
                                          const AlignOptions& options,
                                          const ProgressCallback& progress = {});

/// @brief What `strata register` aligns, and to which state of the map.
struct RegisterOptions {
    ScanSpec scans;     ///< one scan without poses is aligned as it is (its own frame)
    std::string as_of;  ///< align to the map right after this session; empty: the newest
    AlignRequest align;
    ProgressCallback progress;
};

/// @brief An alignment of a scan source and what was aligned.
struct Registration {
    MapAlignment alignment;
    std::string source;  ///< ScanSource::Describe
    size_t scans = 0;
    bool single_scan = false;  ///< one scan in its own frame, else a session in its poses' frame
};

/// @brief Reads the scans and aligns them to the map near the guess. A registration that does
/// not converge is returned (RequireAccepted refuses it), not thrown.
/// @throw the errors of ScanSource::Open, ReadSourceCloud, SelectSnapshot and AlignToMap.
[[nodiscard]] Registration RegisterScans(const store::MapStore& map,
                                         const RegisterOptions& options);

/// @brief AlignmentJson with "source" and "scans": what `strata register --json` prints.
[[nodiscard]] nlohmann::json RegistrationJson(const Registration& r);

}  // namespace strata::pipeline
