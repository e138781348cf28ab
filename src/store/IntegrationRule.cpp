#include "IntegrationRule.hpp"

#include <functional>
#include <sstream>

#include "strata/core/Error.hpp"

namespace strata::store::detail {
namespace {

using integration::IntegrationConfig;

// A field of IntegrationConfig that changes the fused result, as text and back. Limits that
// only bound memory (max_update_bytes, dense_scratch_limit_bytes) are not part of the rule.
struct Field {
    const char* name;
    std::function<std::string(const IntegrationConfig&)> get;
    std::function<bool(IntegrationConfig&, const std::string&)> set;
};

template <typename T>
Field Number(const char* name, T IntegrationConfig::*member) {
    return {name,
            [member](const IntegrationConfig& c) {
                std::ostringstream os;
                os.precision(17);
                os << c.*member;
                return os.str();
            },
            [member](IntegrationConfig& c, const std::string& text) {
                std::istringstream is(text);
                is >> c.*member;
                return !is.fail() && is.eof();
            }};
}

Field Flag(const char* name, bool IntegrationConfig::*member) {
    return {name, [member](const IntegrationConfig& c) { return c.*member ? "true" : "false"; },
            [member](IntegrationConfig& c, const std::string& text) {
                c.*member = text == "true";
                return text == "true" || text == "false";
            }};
}

const std::vector<Field>& Fields() {
    static const std::vector<Field> fields = {
        Number("max_range_m", &IntegrationConfig::max_range_m),
        Number("min_range_m", &IntegrationConfig::min_range_m),
        Number("prob_hit", &IntegrationConfig::prob_hit),
        Number("prob_miss", &IntegrationConfig::prob_miss),
        Number("clamp_min_prob", &IntegrationConfig::clamp_min_prob),
        Number("clamp_max_prob", &IntegrationConfig::clamp_max_prob),
        Number("label_vote_weight", &IntegrationConfig::label_vote_weight),
        Flag("points_only", &IntegrationConfig::points_only),
        Flag("keep_point_means", &IntegrationConfig::keep_point_means),
    };
    return fields;
}

constexpr const char* kPrefix = "integration.";

}  // namespace

void WriteIntegrationRule(const Database& db, const IntegrationConfig& config, bool replace) {
    Statement q(db, replace ? "INSERT OR REPLACE INTO settings(key, value) VALUES (?, ?)"
                            : "INSERT OR IGNORE INTO settings(key, value) VALUES (?, ?)");
    for (const Field& f : Fields()) {
        q.Bind(1, std::string(kPrefix) + f.name).Bind(2, f.get(config)).Run();
        q.Reset();
    }
}

IntegrationConfig ReadIntegrationRule(const std::map<std::string, std::string>& settings,
                                      const Database& db) {
    IntegrationConfig config;
    for (const Field& f : Fields()) {
        const auto it = settings.find(std::string(kPrefix) + f.name);
        if (it == settings.end()) {
            throw FormatError(db.file().string() + ": setting '" + kPrefix + f.name +
                              "' is missing");
        }
        if (!f.set(config, it->second)) {
            throw FormatError(db.file().string() + ": setting '" + kPrefix + f.name +
                              "' is damaged ('" + it->second + "')");
        }
    }
    return config;
}

std::vector<std::string> RuleConflicts(const IntegrationConfig& map,
                                       const IntegrationConfig& given) {
    std::vector<std::string> out;
    for (const Field& f : Fields()) {
        const std::string a = f.get(map), b = f.get(given);
        if (a != b) out.push_back(std::string(f.name) + ": the map's " + a + ", given " + b);
    }
    return out;
}

}  // namespace strata::store::detail
