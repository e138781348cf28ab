// strata: one program, one subcommand per file. The only place that prints errors and exits.
#include <cstdlib>
#include <exception>
#include <iostream>

#include "Commands.hpp"

int main(int argc, char** argv) {
    CLI::App app{"strata: a GPU-free voxel database for LiDAR maps"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "strata 0.1.0");
    strata::tools::RegisterIntegrate(app);
    strata::tools::RegisterInfo(app);
    strata::tools::RegisterExport(app);
    strata::tools::RegisterSession(app);
    strata::tools::RegisterMaintenance(app);
    strata::tools::RegisterDiff(app);
    strata::tools::RegisterWalls(app);
    strata::tools::RegisterVehicles(app);
    strata::tools::RegisterRegister(app);
    strata::tools::RegisterFloors(app);
    strata::tools::RegisterDemo(app);
    strata::tools::RegisterSimulate(app);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    } catch (const std::exception& e) {
        std::cerr << "strata: error: " << e.what() << "\n";
        return EXIT_FAILURE;
    }
    return EXIT_SUCCESS;
}
