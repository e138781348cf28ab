#include "strata/recordings/TransformTree.hpp"

#include <algorithm>
#include <set>

#include "strata/core/Error.hpp"
#include "strata/core/Scan.hpp"

namespace strata::recordings {
namespace {

std::string Describe(const std::string& parent, const std::string& child) {
    return "tf edge " + parent + " -> " + child;
}

}  // namespace

void TransformTree::Add(const StampedTransform& transform, bool is_static) {
    auto [it, added] = edges_.try_emplace(transform.child);
    Edge& edge = it->second;
    if (added) {
        edge.parent = transform.parent;
        edge.is_static = is_static;
    } else if (edge.parent != transform.parent) {
        throw FormatError("frame " + transform.child + " has two parents in the tf tree, " +
                          edge.parent + " and " + transform.parent);
    } else if (edge.is_static != is_static) {
        throw FormatError(Describe(edge.parent, transform.child) +
                          " is published both on /tf_static and on /tf");
    }
    if (is_static) {
        // A static edge republished keeps its newest pose (a latched topic may repeat it).
        edge.samples.assign(1, {transform.stamp_ns, transform.T_parent_child});
        return;
    }
    if (!edge.samples.empty() && transform.stamp_ns < edge.samples.back().first)
        edge.sorted = false;
    edge.samples.emplace_back(transform.stamp_ns, transform.T_parent_child);
}

std::vector<std::string> TransformTree::Frames() const {
    std::set<std::string> frames;
    for (const auto& [child, edge] : edges_) {
        frames.insert(child);
        frames.insert(edge.parent);
    }
    return {frames.begin(), frames.end()};
}

std::string TransformTree::Root() const {
    std::vector<std::string> roots;
    for (const std::string& f : Frames()) {
        if (edges_.count(f) == 0) roots.push_back(f);
    }
    if (roots.empty()) throw NotFoundError("the recording has no tf transforms");
    if (roots.size() > 1) {
        std::string names;
        for (const std::string& r : roots) names += (names.empty() ? "" : ", ") + r;
        throw InvalidArgumentError("the tf tree has " + std::to_string(roots.size()) + " roots (" +
                                   names + "): name the fixed frame");
    }
    return roots.front();
}

std::vector<const TransformTree::Edge*> TransformTree::Chain(const std::string& frame,
                                                             const std::string& stop) const {
    std::vector<const Edge*> chain;
    std::string f = frame;
    while (f != stop) {
        const auto it = edges_.find(f);
        if (it == edges_.end()) break;
        chain.push_back(&it->second);
        f = it->second.parent;
        if (chain.size() > edges_.size()) throw FormatError("the tf tree has a cycle through " + f);
    }
    return chain;
}

std::string TransformTree::CommonAncestor(const std::string& a, const std::string& b) const {
    const std::vector<std::string> frames = Frames();
    for (const std::string& f : {a, b}) {
        if (!std::binary_search(frames.begin(), frames.end(), f)) {
            throw NotFoundError("frame " + f + " is not in the tf tree");
        }
    }
    std::vector<std::string> up_a{a};
    for (const Edge* e : Chain(a, "")) up_a.push_back(e->parent);
    std::string f = b;
    while (true) {
        if (std::find(up_a.begin(), up_a.end(), f) != up_a.end()) return f;
        const auto it = edges_.find(f);
        if (it == edges_.end()) break;
        f = it->second.parent;
    }
    throw NotFoundError("frames " + a + " and " + b + " are not connected in the tf tree");
}

void TransformTree::Sort(const Edge& edge) const {
    if (edge.sorted) return;
    std::stable_sort(edge.samples.begin(), edge.samples.end(),
                     [](const auto& x, const auto& y) { return x.first < y.first; });
    edge.sorted = true;
}

Eigen::Isometry3d TransformTree::At(const std::string& child, const Edge& edge,
                                    int64_t t_ns) const {
    if (edge.is_static) return edge.samples.front().second;
    Sort(edge);
    const auto& s = edge.samples;
    if (t_ns < s.front().first || t_ns > s.back().first) {
        throw RefusedError(Describe(edge.parent, child) + " is known from " +
                           FormatStamp(s.front().first) + " to " + FormatStamp(s.back().first) +
                           ", not at " + FormatStamp(t_ns) + " (strata does not extrapolate)");
    }
    const auto after = std::lower_bound(s.begin(), s.end(), t_ns,
                                        [](const auto& x, int64_t t) { return x.first < t; });
    if (after->first == t_ns) return after->second;
    const auto before = after - 1;
    const double alpha = static_cast<double>(t_ns - before->first) /
                         static_cast<double>(after->first - before->first);
    return core::Interpolate(before->second, after->second, alpha);
}

Eigen::Isometry3d TransformTree::Lookup(const std::string& fixed, const std::string& frame,
                                        int64_t t_ns) const {
    const std::string common = CommonAncestor(fixed, frame);
    // T_common_frame: the edges from frame up, composed from the top down.
    const auto compose = [&](const std::string& from) {
        Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
        std::string child = from;
        for (const Edge* e : Chain(from, common)) {
            T = At(child, *e, t_ns) * T;
            child = e->parent;
        }
        return T;
    };
    return compose(fixed).inverse() * compose(frame);
}

std::optional<std::pair<int64_t, int64_t>> TransformTree::Span(const std::string& fixed,
                                                               const std::string& frame) const {
    const std::string common = CommonAncestor(fixed, frame);
    std::optional<std::pair<int64_t, int64_t>> span;
    for (const std::string& from : {fixed, frame}) {
        for (const Edge* e : Chain(from, common)) {
            if (e->is_static) continue;
            Sort(*e);
            const int64_t first = e->samples.front().first, last = e->samples.back().first;
            span = span ? std::pair{std::max(span->first, first), std::min(span->second, last)}
                        : std::pair{first, last};
        }
    }
    if (span && span->first > span->second) {
        throw RefusedError("the tf edges between " + fixed + " and " + frame +
                           " were never all known at one time");
    }
    return span;
}

TransformTree::EdgeSummary TransformTree::Summary(const std::string& child,
                                                  const Edge& edge) const {
    Sort(edge);
    return {edge.parent,
            child,
            edge.is_static,
            edge.samples.size(),
            edge.samples.front().first,
            edge.samples.back().first};
}

std::vector<TransformTree::EdgeSummary> TransformTree::Edges() const {
    std::vector<EdgeSummary> out;
    for (const auto& [child, edge] : edges_) out.push_back(Summary(child, edge));
    return out;
}

std::vector<TransformTree::EdgeSummary> TransformTree::EdgesBetween(
    const std::string& fixed, const std::string& frame) const {
    const std::string common = CommonAncestor(fixed, frame);
    std::vector<EdgeSummary> out;
    for (const std::string& from : {fixed, frame}) {
        std::string child = from;
        for (const Edge* e : Chain(from, common)) {
            out.push_back(Summary(child, *e));
            child = e->parent;
        }
    }
    return out;
}

TransformTree ReadTransformTree(const Recording& recording) {
    TransformTree tree;
    std::vector<std::string> topics;
    for (const char* t : {"/tf_static", "/tf"}) {
        if (recording.info().Find(t) != nullptr) topics.emplace_back(t);
    }
    if (topics.empty()) return tree;
    const std::string file = recording.info().path.string();
    recording.Read(topics, [&](const Message& m) {
        for (const StampedTransform& t : DecodeTfMessage(m, file)) {
            tree.Add(t, m.topic->name == "/tf_static");
        }
    });
    return tree;
}

}  // namespace strata::recordings
