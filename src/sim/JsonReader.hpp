#include "strata/core/Error.hpp"
#pragma once

// Strict reading of scene JSON (private): a missing key takes its default, an unknown key or a
// wrong type is an error naming the file and the key path (docs/architecture.md, "Code style").
#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace strata::sim::detail {

class JsonReader {
public:
    JsonReader(const nlohmann::json& j, std::string source, std::string path)
        : j_(j), source_(std::move(source)), path_(std::move(path)) {
        if (!j_.is_object()) Fail("expected a JSON object");
    }

    [[nodiscard]] bool Has(const std::string& key) {
        used_.insert(key);
        return j_.contains(key);
    }
    [[nodiscard]] const nlohmann::json& Raw(const std::string& key) {
        if (!Has(key)) Fail("missing key '" + key + "'");
        return j_.at(key);
    }
    template <typename T>
    [[nodiscard]] T Get(const std::string& key, const T& fallback) {
        return Has(key) ? Convert<T>(key) : fallback;
    }
    template <typename T>
    [[nodiscard]] T Require(const std::string& key) {
        if (!Has(key)) Fail("missing key '" + key + "'");
        return Convert<T>(key);
    }
    /// A number in [lo, hi]; out of range (NaN, infinite) is an error naming the key.
    [[nodiscard]] double Within(const std::string& key, double fallback, double lo, double hi) {
        const double v = Get<double>(key, fallback);
        if (!(v >= lo && v <= hi)) Fail("'" + key + "' must be in " + Bounds(lo, hi));
        return v;
    }
    /// [min, max] with lo <= min <= max <= hi.
    [[nodiscard]] std::pair<double, double> Interval(const std::string& key,
                                                     std::pair<double, double> fallback, double lo,
                                                     double hi) {
        if (!Has(key)) return fallback;
        const auto v = Require<std::vector<double>>(key);
        if (v.size() != 2 || !(v[0] >= lo && v[0] <= v[1] && v[1] <= hi)) {
            Fail("'" + key + "' must be [min, max] within " + Bounds(lo, hi));
        }
        return {v[0], v[1]};
    }
    /// [x, y] (or the first two of [x, y, z]).
    [[nodiscard]] Eigen::Vector2d Vec2(const std::string& key) {
        const auto v = Require<std::vector<double>>(key);
        if (v.size() < 2 || v.size() > 3) Fail("'" + key + "' must be [x, y]");
        return {v[0], v[1]};
    }
    /// [x, y, z]; [x, y] gives z = `missing_z`.
    [[nodiscard]] Eigen::Vector3d Vec3(const std::string& key, double missing_z) {
        const auto v = Require<std::vector<double>>(key);
        if (v.size() < 2 || v.size() > 3) Fail("'" + key + "' must be [x, y] or [x, y, z]");
        return {v[0], v[1], v.size() == 3 ? v[2] : missing_z};
    }
    [[nodiscard]] JsonReader Child(const std::string& key) {
        return JsonReader(Raw(key), source_, Sub(key));
    }
    /// Elements of an array-valued key as readers (objects) with indexed paths.
    [[nodiscard]] std::vector<JsonReader> Items(const std::string& key) {
        std::vector<JsonReader> items;
        if (!Has(key)) return items;
        const nlohmann::json& a = j_.at(key);
        if (!a.is_array()) Fail("'" + key + "' must be an array");
        for (size_t i = 0; i < a.size(); ++i) {
            items.emplace_back(a[i], source_, Sub(key) + "[" + std::to_string(i) + "]");
        }
        return items;
    }
    /// Throws FormatError for keys that were never asked for (typos, unknown keys).
    void Finish() const {
        for (const auto& item : j_.items()) {
            if (used_.count(item.key()) == 0) Fail("unknown key '" + item.key() + "'");
        }
    }
    [[noreturn]] void Fail(const std::string& what) const {
        throw FormatError(source_ + ": " + (path_.empty() ? "" : path_ + ": ") + what);
    }
    [[nodiscard]] const std::string& source() const { return source_; }
    [[nodiscard]] const std::string& path() const { return path_; }

private:
    template <typename T>
    [[nodiscard]] T Convert(const std::string& key) {
        try {
            return j_.at(key).get<T>();
        } catch (const nlohmann::json::exception&) {
            Fail("'" + key + "' has the wrong type");
        }
    }
    [[nodiscard]] static std::string Bounds(double lo, double hi) {
        return "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    }
    [[nodiscard]] std::string Sub(const std::string& key) const {
        return path_.empty() ? key : path_ + "." + key;
    }

    const nlohmann::json& j_;
    std::string source_;
    std::string path_;
    std::set<std::string> used_;  // keys asked for, so Finish can report unknown ones
};

}  // namespace strata::sim::detail
