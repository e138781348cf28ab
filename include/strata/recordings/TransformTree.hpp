#pragma once
// A recording's transform tree (/tf and /tf_static): each edge a parent, a child and the child's
// pose in the parent over time. Poses between two samples of an edge are interpolated (linear
// translation, slerp rotation); outside an edge's samples they are refused, never extrapolated.
// Static edges hold at every time (docs/recordings.md, "Poses").

#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "strata/recordings/Messages.hpp"

namespace strata::recordings {

class TransformTree {
public:
    /// @brief Adds one sample of an edge. An edge is static or dynamic for good: the first sample
    /// decides. Samples may come in any order.
    /// @throw FormatError when `child` already has another parent (a tf tree has one per frame)
    /// or the edge was static and now is not, or the other way round.
    void Add(const StampedTransform& transform, bool is_static);

    /// @brief Every frame, sorted.
    [[nodiscard]] std::vector<std::string> Frames() const;

    /// @brief The frame that is no edge's child, when there is exactly one (the default fixed
    /// frame). @throw NotFoundError when the tree is empty; InvalidArgumentError naming the roots
    /// when there are several (the user then names the fixed frame).
    [[nodiscard]] std::string Root() const;

    /// @brief The pose of `frame` in `fixed` at `t_ns`, composed over the edges between them (up
    /// to their lowest common ancestor; edges above it are not needed).
    /// @throw NotFoundError when either frame is not in the tree or they are not connected;
    /// RefusedError naming the edge and its span when `t_ns` lies outside a dynamic edge's
    /// samples on the way.
    [[nodiscard]] Eigen::Isometry3d Lookup(const std::string& fixed, const std::string& frame,
                                           int64_t t_ns) const;

    /// @brief The times at which Lookup(fixed, frame, t) is answered: the intersection of the
    /// spans of the dynamic edges between them; std::nullopt when every edge between is static.
    /// Throws as Lookup does for unknown or unconnected frames, and RefusedError when the spans
    /// do not overlap.
    [[nodiscard]] std::optional<std::pair<int64_t, int64_t>> Span(const std::string& fixed,
                                                                  const std::string& frame) const;

    /// @brief One edge as `strata bag info` lists it.
    struct EdgeSummary {
        std::string parent, child;
        bool is_static = false;
        size_t samples = 0;
        int64_t first_ns = 0, last_ns = 0;
    };
    [[nodiscard]] std::vector<EdgeSummary> Edges() const;
    /// @brief The edges between `fixed` and `frame` (as Lookup composes them).
    [[nodiscard]] std::vector<EdgeSummary> EdgesBetween(const std::string& fixed,
                                                        const std::string& frame) const;

private:
    struct Edge {
        std::string parent;
        bool is_static = false;
        mutable bool sorted = true;
        mutable std::vector<std::pair<int64_t, Eigen::Isometry3d>> samples;
    };

    // The edges from `frame` up to (not including) `stop`, child first; all the way up when `stop`
    // is empty.
    [[nodiscard]] std::vector<const Edge*> Chain(const std::string& frame,
                                                 const std::string& stop) const;
    [[nodiscard]] std::string CommonAncestor(const std::string& a, const std::string& b) const;
    [[nodiscard]] Eigen::Isometry3d At(const std::string& child, const Edge& edge,
                                       int64_t t_ns) const;
    void Sort(const Edge& edge) const;
    [[nodiscard]] EdgeSummary Summary(const std::string& child, const Edge& edge) const;

    std::map<std::string, Edge> edges_;  // by child frame
};

/// @brief The transform tree of a recording's /tf_static and /tf (an empty tree when it has
/// neither).
[[nodiscard]] TransformTree ReadTransformTree(const Recording& recording);

}  // namespace strata::recordings
