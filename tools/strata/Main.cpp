// strata: one program, one subcommand per file. The only place that prints errors and exits.
#include <cstdlib>
#include <exception>
#include <iostream>

#include "Commands.hpp"
#include "strata/core/Error.hpp"

namespace {

// Exit codes, one per kind of strata::Error (README, "Exit codes"); scripts branch on these.
enum ExitCode : int {
    kFailed = 1,     // any other error: a file that cannot be written, an unexpected failure
    kUsage = 2,      // a bad argument or option (CLI11's parse errors too)
    kLocked = 3,     // another strata process writes the map: try again later
    kRefused = 4,    // the command ran and declined its result (an alignment, a floor height)
    kNotFound = 5,   // a map, session or input file that does not exist
    kBadFormat = 6,  // an input or map file that is malformed or of a newer format
};

int ExitCodeOf(const std::exception& e) {
    if (dynamic_cast<const strata::InvalidArgumentError*>(&e)) return kUsage;
    if (dynamic_cast<const std::invalid_argument*>(&e)) return kUsage;
    if (dynamic_cast<const strata::MapLockedError*>(&e)) return kLocked;
    if (dynamic_cast<const strata::RefusedError*>(&e)) return kRefused;
    if (dynamic_cast<const strata::NotFoundError*>(&e)) return kNotFound;
    if (dynamic_cast<const strata::FormatError*>(&e)) return kBadFormat;
    return kFailed;
}

}  // namespace

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
    strata::tools::RegisterView(app);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = app.exit(e);  // prints the help, the version or the problem
        return code == 0 ? EXIT_SUCCESS : kUsage;
    } catch (const std::exception& e) {
        std::cerr << "strata: error: " << e.what() << "\n";
        return ExitCodeOf(e);
    }
    return EXIT_SUCCESS;
}
