#pragma once
// Change detection scored against the simulator's edits (ground_truth.json): shared by the
// street's change test (tests/change) and the district's accuracy test (tests/sim).
#include <Eigen/Core>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "strata/change/ChangeDetection.hpp"
#include "strata/io/KittiSequence.hpp"

namespace strata::testing {

// Points of an edited object count for it when inside its box grown by this much (range noise).
inline constexpr double kEditBoxMarginM = 0.3;
// An edit is observable when at least this many of its voxels could be seen as changed.
inline constexpr size_t kMinObservableVoxels = 8;

/// One edit of ground_truth.json: an oriented box that was added or removed.
struct TruthEdit {
    int object = 0;
    std::string name, change, kind;
    Eigen::Vector3d center = Eigen::Vector3d::Zero(), size = Eigen::Vector3d::Zero();
    double yaw_deg = 0.0;
    [[nodiscard]] bool Contains(const Eigen::Vector3d& p, double margin) const;
};

/// The edits of a ground_truth.json (in its session frame).
[[nodiscard]] std::vector<TruthEdit> ReadTruthEdits(const std::filesystem::path& ground_truth);

/// What the simulated points of one session hit: every voxel, and the points of some objects.
struct SessionHits {
    openvdb::BoolGrid::Ptr all = openvdb::BoolGrid::create(false);
    std::map<int, std::vector<Eigen::Vector3d>> by_object;
};
[[nodiscard]] SessionHits ReadSessionHits(const io::KittiSequence& seq,
                                          const std::set<int>& objects, double voxel);
/// Adds one scan's points to `hits` (ReadSessionHits one scan at a time).
void AddSessionHits(SessionHits& hits, const core::Scan& scan, const std::set<int>& objects,
                    double voxel);

/// Two sessions of a simulated scene, as the map store saw them, and the edits between them.
struct ChangeCase {
    double voxel = 0.2;
    std::vector<TruthEdit> edits;  ///< of session b relative to session a
    change::Observation a, b;
    SessionHits hits_a, hits_b;
};

struct ChangeScore {
    double precision = 0.0, recall = 0.0, iou = 0.0;
    size_t objects = 0, observable = 0;
};

/// Scores a query: objects are attributed to the edit of their kind holding most of their voxels
/// (inside its box grown by the margin); per edit the detected voxels inside its box against the
/// voxels a perfect detector would report. `strict` also leaves out voxels the other side's
/// points hit. `table` prints the per-edit rows docs/change.md shows.
[[nodiscard]] ChangeScore ScoreChanges(const ChangeCase& c, const change::ChangeQuery& query,
                                       bool strict, bool table);

}  // namespace strata::testing
