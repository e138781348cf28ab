#pragma once
// Private to the store: the integration rule a map was built with, as `integration.*` rows of the
// settings table (docs/store.md, "The integration rule").

#include <map>
#include <string>
#include <vector>

#include "Sqlite.hpp"
#include "strata/integration/IntegrationConfig.hpp"

namespace strata::store::detail {

/// Writes every field of `config` that changes the fused result; `replace` false keeps rows that
/// exist already.
void WriteIntegrationRule(const Database& db, const integration::IntegrationConfig& config,
                          bool replace);
/// The rule from the settings rows; throws FormatError naming the catalog for a damaged row.
[[nodiscard]] integration::IntegrationConfig ReadIntegrationRule(
    const std::map<std::string, std::string>& settings, const Database& db);
/// One line per field that differs ("max_range_m: the map's 50, given 30"); empty when equal.
[[nodiscard]] std::vector<std::string> RuleConflicts(const integration::IntegrationConfig& map,
                                                     const integration::IntegrationConfig& given);

}  // namespace strata::store::detail
