#pragma once

#include <CLI/CLI.hpp>

#include "strata/pipeline/Ranks.hpp"

// Each subcommand lives in its own file and registers itself on the top-level app.
// Registration adds options and a callback; the callback does the work and throws on failure.
namespace strata::tools {

void RegisterIntegrate(CLI::App& app);
void RegisterInfo(CLI::App& app);
void RegisterExport(CLI::App& app);
void RegisterDemo(CLI::App& app);
void RegisterSimulate(CLI::App& app);
void RegisterSession(CLI::App& app);
void RegisterMaintenance(CLI::App& app);
void RegisterDiff(CLI::App& app);
void RegisterWalls(CLI::App& app);
void RegisterVehicles(CLI::App& app);
void RegisterDynamic(CLI::App& app);
void RegisterRegister(CLI::App& app);
void RegisterFloors(CLI::App& app);
void RegisterView(CLI::App& app);
void RegisterBag(CLI::App& app);
void RegisterOdometry(CLI::App& app);

/// The processes this command runs on: this one alone, or the ranks of `mpirun` (docs/scale.md).
/// Commands that share their work (integrate) pass it to the pipeline; the others run on
/// rank 0 alone.
[[nodiscard]] const pipeline::Ranks& CommandRanks();

}  // namespace strata::tools
