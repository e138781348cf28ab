#include <array>
#include <cmath>

#include "District.hpp"
#include "ObjectGeometry.hpp"
#include "Rng.hpp"

// The facades of a district's blocks: the five wall kinds of the wall-slant study along every
// block side, adjoining walls at some corners, bushes in front of some flat facades
// (docs/simulator.md, "Districts").
namespace strata::sim::detail {
namespace {

using nlohmann::json;

constexpr uint64_t kFacadeKey = 0xFACADE5;
constexpr double kCornerMarginM = 1.0;  // a bare corner: first facade this far from it, + a gap
constexpr double kArmShare = 0.4;       // an adjoining arm takes at most this share of a side
constexpr double kCurveRadiusM = 3.0;   // curved_edge arcs (as street.json)
constexpr double kDoorOffsetM = 0.15;   // a sliding door runs this far in front of its wall
constexpr double kOpeningWidthM = 6.0, kOpeningHeightM = 3.8, kDoorHeightM = 4.0;
constexpr double kBushFromFacadeM = 0.8;
const char* const kSideNames[4] = {"s", "w", "n", "e"};
const char* const kCornerNames[4] = {"se", "sw", "nw", "ne"};

// A block side walked with its street on the left (clockwise around the block).
struct Side {
    Eigen::Vector2d start, d;
    double length = 0.0;
    Segment faces;  // the street segment in front
    [[nodiscard]] Eigen::Vector2d At(double t) const { return start + t * d; }
    [[nodiscard]] Eigen::Vector2d Front() const { return {-d.y(), d.x()}; }
};

class BlockBuilder {
public:
    BlockBuilder(const DistrictConfig& c, SceneAssembler& a, DistrictPlan& plan, int i, int j)
        : c_(c), a_(a), plan_(plan), rng_(HashKey(a.seed(), kFacadeKey, uint64_t(i) * 64 + j)) {
        name_ = "b" + std::to_string(i) + "_" + std::to_string(j) + "_";
        const Eigen::Vector2d lo = c.BlockMin(i, j) + Eigen::Vector2d::Constant(c.sidewalk);
        const Eigen::Vector2d hi = lo + c.block_size - Eigen::Vector2d::Constant(2 * c.sidewalk);
        const Eigen::Vector2d size = hi - lo;
        sides_[0] = {{hi.x(), lo.y()}, {-1, 0}, size.x(), {0, j, i}};
        sides_[1] = {lo, {0, 1}, size.y(), {1, i, j}};
        sides_[2] = {{lo.x(), hi.y()}, {1, 0}, size.x(), {0, j + 1, i}};
        sides_[3] = {hi, {0, -1}, size.y(), {1, i + 1, j}};
    }

    void Build() {
        // Step 1: each corner gets an adjoining wall (one arm on each side) or stays bare.
        const FacadeKind* adjoining = Kind("adjoining");
        for (int q = 0; q < 4; ++q) {
            const int p = (q + 3) % 4;  // the side that ends at corner q
            const double u = rng_.Uniform();
            const double arm_before = rng_.Uniform();
            const double arm_after = rng_.Uniform();
            if (adjoining == nullptr || u >= c_.corners) {
                start_[q] = end_[p] = kCornerMarginM;
                continue;
            }
            const DistrictRange& len = adjoining->length;
            start_[q] =
                std::min(len.lo + arm_after * (len.hi - len.lo), kArmShare * sides_[q].length);
            end_[p] =
                std::min(len.lo + arm_before * (len.hi - len.lo), kArmShare * sides_[p].length);
            json w = Common(name_ + kCornerNames[q], "adjoining", *adjoining);
            w["start"] = JsonXy(sides_[p].At(sides_[p].length - end_[p]));
            w["corner"] = JsonXy(sides_[q].start);
            w["end"] = JsonXy(sides_[q].At(start_[q]));
            (void)AddDistrictItem(a_, "walls", w);
        }
        // Step 2: facades along each side, a gap between neighbours.
        for (int q = 0; q < 4; ++q) FillSide(q);
    }

private:
    [[nodiscard]] const FacadeKind* Kind(const std::string& name) const {
        for (const FacadeKind& k : c_.kinds) {
            if (k.kind == name) return &k;
        }
        return nullptr;
    }

    [[nodiscard]] const FacadeKind* PickKind() {
        double total = 0.0;
        for (const FacadeKind& k : c_.kinds) total += k.kind == "adjoining" ? 0.0 : k.weight;
        double u = rng_.Uniform() * total;
        for (const FacadeKind& k : c_.kinds) {
            if (k.kind == "adjoining" || k.weight <= 0.0) continue;
            if (u < k.weight) return &k;
            u -= k.weight;
        }
        return nullptr;
    }

    // Height, slant, lean and a window grid, drawn in this order for every wall.
    json Common(const std::string& name, const char* kind, const FacadeKind& k) {
        const double height = rng_.Uniform(c_.height.lo, c_.height.hi);
        const double slant = k.slant_deg[rng_.Next() % k.slant_deg.size()];
        const bool back = rng_.Uniform() < 0.5;
        const bool windows = rng_.Uniform() < c_.windows;
        const double width = rng_.Uniform(1.0, 1.5);
        const double window_height = rng_.Uniform(1.3, 1.8);
        const double spacing = width + rng_.Uniform(1.2, 2.2);
        const double storey = rng_.Uniform(3.0, 3.6);
        const bool recessed = rng_.Uniform() < 0.25;
        json w = {{"name", name},       {"kind", kind},
                  {"height", height},   {"thickness", c_.thickness},
                  {"slant_deg", slant}, {"lean", back ? "back" : "front"}};
        if (windows) {
            w["windows"] = {{"width", width},
                            {"height", window_height},
                            {"spacing", spacing},
                            {"storey", storey}};
            if (recessed) w["windows"]["depth"] = 0.5 * c_.thickness;
        }
        return w;
    }

    void FillSide(int q) {
        const Side& side = sides_[q];
        const double end = side.length - end_[q] - c_.gap.lo;
        double t = start_[q] + rng_.Uniform(c_.gap.lo, c_.gap.hi);
        for (int n = 0;; ++n) {
            const FacadeKind* kind = PickKind();
            if (kind == nullptr) return;
            double len = rng_.Uniform(kind->length.lo, kind->length.hi);
            const double gap = rng_.Uniform(c_.gap.lo, c_.gap.hi);
            if (t + len + Curve(*kind, len) > end) {
                // The rest of the side: a flat facade when one fits, else the side is done.
                const FacadeKind* flat = Kind("flat");
                if (flat == nullptr || flat->weight <= 0.0 || end - t < flat->length.lo) return;
                kind = flat;
                len = std::min(end - t, flat->length.hi);
            }
            AddFacade(side, name_ + kSideNames[q] + std::to_string(n), *kind, t, len);
            t += len + Curve(*kind, len) + gap;
        }
    }

    // How far an arc at the end of the straight part reaches along the side.
    [[nodiscard]] static double Curve(const FacadeKind& k, double len) {
        if (k.kind == "curved_edge") return kCurveRadiusM;
        return k.kind == "half_curved" ? 2.0 * len / M_PI : 0.0;  // an arc as long as the half
    }

    void AddFacade(const Side& side, const std::string& name, const FacadeKind& k, double t,
                   double len) {
        const bool door = k.kind == "sliding_door";
        json w = Common(name, door ? "flat" : k.kind.c_str(), k);
        w["start"] = JsonXy(side.At(t));
        w["end"] = JsonXy(side.At(t + len));
        if (k.kind == "curved_edge") w["curve_radius"] = kCurveRadiusM;
        if (k.kind == "curved_edge" || k.kind == "half_curved") w["curve_deg"] = 90.0;
        // A sliding door: a warehouse opening, the door half open in front of it (street.json).
        const double opening = rng_.Uniform(1.5, len - kOpeningWidthM - 1.5);
        if (door) {
            w.erase("windows");
            w["openings"] = json::array(
                {json{{"u", {opening, opening + kOpeningWidthM}}, {"v", {0.0, kOpeningHeightM}}}});
            const Eigen::Vector2d front = kDoorOffsetM * side.Front();
            const json d = {{"name", name + "_door"},
                            {"kind", "sliding_door"},
                            {"start", JsonXy(side.At(t + opening - 1.5) + front)},
                            {"end", JsonXy(side.At(t + opening + kOpeningWidthM - 1.5) + front)},
                            {"height", std::min(kDoorHeightM, w["height"].get<double>())}};
            (void)AddDistrictItem(a_, "walls", d);
        }
        (void)AddDistrictItem(a_, "walls", w);
        if (k.kind != "flat") return;
        // Plain flat facades can be cut by an edit, and some have a bush in front.
        plan_.walls.push_back({side.faces, name, side.At(t), side.At(t + len), false});
        const double bush = rng_.Uniform();
        const double u = rng_.Uniform(1.5, len - 1.5);
        const double rx = rng_.Uniform(0.8, 1.5);
        if (bush >= c_.bushes) return;
        const bool along_x = std::abs(side.d.x()) > 0.5;
        const json b = {{"name", name + "_bush"},
                        {"at", JsonXy(side.At(t + u) + kBushFromFacadeM * side.Front())},
                        {"radius", along_x ? json{rx, 0.6, 0.6} : json{0.6, rx, 0.6}}};
        plan_.bushes.push_back(PlantItem(side.faces, ObjectBox(AddDistrictItem(a_, "bushes", b))));
    }

    const DistrictConfig& c_;
    SceneAssembler& a_;
    DistrictPlan& plan_;
    Rng rng_;
    std::string name_;
    std::array<Side, 4> sides_;
    std::array<double, 4> start_{}, end_{};  // reserved at each side's start and end
};

}  // namespace

void AddDistrictFacades(const DistrictConfig& c, SceneAssembler& a, DistrictPlan& plan) {
    for (int i = 0; i < c.blocks.x(); ++i) {
        for (int j = 0; j < c.blocks.y(); ++j) BlockBuilder(c, a, plan, i, j).Build();
    }
}

}  // namespace strata::sim::detail
