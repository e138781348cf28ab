#include <cmath>
#include <functional>

#include "District.hpp"
#include "ObjectGeometry.hpp"
#include "Rng.hpp"
#include "strata/core/Error.hpp"

// Generated edits between a district's sessions: cars that leave, move and arrive, containers
// placed, facades cut and plants grown, where a session and the one before both drive
// (docs/simulator.md, "Districts").
namespace strata::sim::detail {
namespace {

using nlohmann::json;

constexpr uint64_t kEditKey = 0xED175;
constexpr double kMinEditSpacingM = 8.0;  // between two edits of one session (separate changes)
constexpr double kCutLengthM = 4.0;       // a demolished facade segment (as street_two_sessions)
constexpr double kCutEndMarginM = 2.5;    // keeps the cut off the wall's ends
constexpr double kGrowScale = 1.6;        // as street_two_sessions.json

class EditPicker {
public:
    EditPicker(const DistrictConfig& c, size_t k, SceneAssembler& a)
        : c_(c), k_(k), a_(a), rng_(HashKey(a.seed(), kEditKey, k)) {}

    // Straddles a line x = n * across or y = n * across (a tile border), when asked for.
    [[nodiscard]] bool Across(const Eigen::AlignedBox2d& box) const {
        if (c_.edits_across <= 0.0) return false;
        const Eigen::Vector2d lo = box.min() / c_.edits_across, hi = box.max() / c_.edits_across;
        return std::floor(lo.x()) != std::floor(hi.x()) || std::floor(lo.y()) != std::floor(hi.y());
    }
    [[nodiscard]] bool Eligible(const Segment& seg, const Eigen::Vector2d& at) const {
        if (!Drives(c_.sessions[k_], seg) || !Drives(c_.sessions[k_ - 1], seg)) return false;
        for (const Eigen::Vector2d& t : taken_) {
            if ((t - at).norm() < kMinEditSpacingM) return false;
        }
        return true;
    }
    // One of the candidates that fit, those across a tile border first; -1 for none.
    template <typename T>
    int Pick(const std::vector<T>& items, const std::function<bool(const T&)>& fits,
             const std::function<Eigen::AlignedBox2d(const T&)>& box) {
        std::vector<int> all, across;
        for (size_t i = 0; i < items.size(); ++i) {
            if (!fits(items[i])) continue;
            all.push_back(static_cast<int>(i));
            if (Across(box(items[i]))) across.push_back(static_cast<int>(i));
        }
        const std::vector<int>& from = across.empty() ? all : across;
        if (from.empty()) return -1;
        return from[rng_.Next() % from.size()];
    }
    void Take(const Eigen::Vector2d& at) { taken_.push_back(at); }
    [[noreturn]] void Short(const char* what, int asked) const {
        throw FormatError(a_.spec().source + ": district session '" + c_.sessions[k_].name +
                          "': fewer places than the " + std::to_string(asked) + " '" + what +
                          "' edits asked for where it and the session before both drive");
    }
    [[nodiscard]] Rng& rng() { return rng_; }

private:
    const DistrictConfig& c_;
    size_t k_;
    SceneAssembler& a_;
    Rng rng_;
    std::vector<Eigen::Vector2d> taken_;
};

using Slot = DistrictPlan::Slot;
using Item = DistrictPlan::Item;

}  // namespace

json DistrictEdits(const DistrictConfig& c, size_t k, SceneAssembler& a, DistrictPlan& plan) {
    const DistrictSession& s = c.sessions[k];
    EditPicker pick(c, k, a);
    const std::function<Eigen::AlignedBox2d(const Slot&)> slot_box = [](const Slot& p) {
        return p.box;
    };
    const std::function<bool(const Slot&)> parked = [&](const Slot& p) {
        return !p.occupant.empty() && !p.container && pick.Eligible(p.segment, p.at);
    };
    const std::function<bool(const Slot&)> free = [&](const Slot& p) {
        return p.occupant.empty() && p.freed_in != int(k) && pick.Eligible(p.segment, p.at);
    };
    const auto vacate = [&](Slot& p) {
        pick.Take(p.at);
        p.occupant.clear();
        p.freed_in = static_cast<int>(k);
    };
    const auto fill = [&](Slot& p, const std::string& name, bool container) {
        pick.Take(p.at);
        p.occupant = name;
        p.container = container;
    };
    json edits = json::array();
    // Step 1: cars leave, then cars move to a free place.
    for (int n = 0; n < s.remove; ++n) {
        const int i = pick.Pick(plan.slots, parked, slot_box);
        if (i < 0) pick.Short("remove", s.remove);
        edits.push_back({{"remove", plan.slots[i].occupant}});
        vacate(plan.slots[i]);
    }
    for (int n = 0; n < s.move; ++n) {
        const int i = pick.Pick(plan.slots, parked, slot_box);
        if (i < 0) pick.Short("move", s.move);
        const std::string car = plan.slots[i].occupant;
        vacate(plan.slots[i]);
        const int to = pick.Pick(plan.slots, free, slot_box);
        if (to < 0) pick.Short("move", s.move);
        Slot& p = plan.slots[to];
        edits.push_back({{"move", car}, {"to", JsonXy(p.at)}, {"yaw_deg", p.yaw_deg}});
        fill(p, car, false);
    }
    // Step 2: cars arrive and containers are put down in free places.
    for (int n = 0; n < s.add + s.containers; ++n) {
        const bool container = n >= s.add;
        const int i = pick.Pick(plan.slots, free, slot_box);
        if (i < 0) pick.Short(container ? "containers" : "add", container ? s.containers : s.add);
        Slot& p = plan.slots[i];
        const std::string name =
            (container ? "container" : "arrived") + std::to_string(k) + "_" + std::to_string(n);
        json object = {{"name", name}, {"yaw_deg", p.yaw_deg}};
        if (container) {
            object["center"] = JsonXy(p.at);
        } else {
            object["at"] = JsonXy(p.at);
            object["type"] = c.car_types[pick.rng().Next() % c.car_types.size()];
        }
        edits.push_back({{"add", {{container ? "box" : "vehicle", object}}}});
        fill(p, name, container);
    }
    // Step 3: facades cut over 4 m (across a tile border when one crosses them), plants grown.
    const std::function<Eigen::AlignedBox2d(const Item&)> item_box = [](const Item& w) {
        return Eigen::AlignedBox2d(w.a.cwiseMin(w.b), w.a.cwiseMax(w.b));
    };
    const std::function<bool(const Item&)> cuttable = [&](const Item& w) {
        return !w.used && (w.b - w.a).norm() >= 2 * kCutEndMarginM + kCutLengthM &&
               pick.Eligible(w.segment, 0.5 * (w.a + w.b));
    };
    for (int n = 0; n < s.demolish; ++n) {
        const int i = pick.Pick(plan.walls, cuttable, item_box);
        if (i < 0) pick.Short("demolish", s.demolish);
        Item& w = plan.walls[i];
        const double length = (w.b - w.a).norm();
        const double lo = kCutEndMarginM + 0.5 * kCutLengthM, hi = length - lo;
        double centre = pick.rng().Uniform(lo, hi);
        for (int axis = 0; axis < 2 && c.edits_across > 0.0; ++axis) {
            const double d = w.b[axis] - w.a[axis];
            if (std::abs(d) < 1e-9) continue;
            const double line =
                c.edits_across * std::ceil(std::min(w.a[axis], w.b[axis]) / c.edits_across);
            const double u = (line - w.a[axis]) / d * length;
            if (u >= lo && u <= hi) centre = u;
        }
        edits.push_back({{"demolish", w.name},
                         {"u", {centre - 0.5 * kCutLengthM, centre + 0.5 * kCutLengthM}}});
        w.used = true;
        pick.Take(w.a + (w.b - w.a) * centre / length);
    }
    const std::function<bool(const Item&)> growable = [&](const Item& p) {
        return !p.used && pick.Eligible(p.segment, 0.5 * (p.a + p.b));
    };
    // Bushes first: a tree's crown is mostly above the view of a car's sensor.
    for (int n = 0; n < s.grow; ++n) {
        std::vector<Item>* plants = &plan.bushes;
        int i = pick.Pick(plan.bushes, growable, item_box);
        if (i < 0) {
            plants = &plan.trees;
            i = pick.Pick(plan.trees, growable, item_box);
        }
        if (i < 0) pick.Short("grow", s.grow);
        Item& p = (*plants)[i];
        edits.push_back({{"grow", p.name}, {"scale", kGrowScale}});
        p.used = true;
        pick.Take(0.5 * (p.a + p.b));
    }
    return edits;
}

}  // namespace strata::sim::detail
