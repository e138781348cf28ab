#pragma once
// Test support: a real format-4 map, made from a format-5 map the way strata's format-4 writer
// wrote it (docs/store.md, "Migration"): one file per tile version `tiles/X_Y/vN.vdb` holding the
// fused grids, the layers of every session alive at that commit and the products of the newest
// walls and vehicles commits, and the catalog of format 4 (walls, vehicles and change_sets
// tables, floors as settings rows). No binary fixture is checked in: tests build a map with the
// current writer and rewrite it.

#include <filesystem>

namespace strata::test {

/// Rewrites the format-5 map in `map` (no history dropped by gc) in place as format 4.
void RewriteAsFormat4(const std::filesystem::path& map);

}  // namespace strata::test
