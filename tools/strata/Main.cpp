// strata: one program, one subcommand per file. The only place that prints errors and exits.
#include <malloc.h>

#include <cstdlib>
#include <exception>
#include <iostream>
#include <optional>
#include <streambuf>
#include <string>

#include "Commands.hpp"
#include "Version.hpp"
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

const strata::pipeline::Ranks* g_ranks = nullptr;

// The heap keeps what the program frees for its next allocation (docs/integration.md, "Where the
// whole command's time goes"). glibc's defaults hand a freed block over 128 KiB back to the
// kernel (raising that bound only as far as the largest block freed so far) and trim the heap's
// top once a few hundred KiB of it are free: the tree nodes of every scan's update and every
// tile (a VDB grid's top node alone is 256 KiB) then come back as fresh pages that fault in one
// by one, which was a third of `strata integrate`'s time on BALM. Blocks up to 32 MiB now come
// from the heap, which gives memory back once 64 MiB of its top are free. The price: the peak
// resident memory of `strata integrate` on BALM rose by 17 % (108 -> 127 MB at 0.2 m).
void KeepFreedMemory() {
    (void)mallopt(M_MMAP_THRESHOLD, 32 << 20);
    (void)mallopt(M_TRIM_THRESHOLD, 64 << 20);
}

// Subcommands whose work is shared by the ranks of mpirun; the others run on rank 0 alone.
bool SharesWork(int argc, char** argv) {
    if (argc < 2) return false;
    const std::string command = argv[1];
    return command == "integrate" || command == "walls" || command == "vehicles" ||
           command == "dynamic";
}

// Swallows std::cout and std::cerr while it lives: the output of the ranks other than 0 (rank 0
// reports for all of them, their errors included: pipeline::OnEveryRank).
class Quiet {
public:
    Quiet() : out_(std::cout.rdbuf(&null_)), err_(std::cerr.rdbuf(&null_)) {}
    ~Quiet() {
        std::cout.rdbuf(out_);
        std::cerr.rdbuf(err_);
    }
    Quiet(const Quiet&) = delete;
    Quiet& operator=(const Quiet&) = delete;

private:
    struct Null : std::streambuf {
        int overflow(int c) override { return c; }
    } null_;
    std::streambuf* out_;
    std::streambuf* err_;
};

// Parses and runs one subcommand on `ranks`.
int RunCommand(int argc, char** argv, const strata::pipeline::Ranks& ranks) {
    g_ranks = &ranks;
    std::optional<Quiet> quiet;
    if (!ranks.root()) {
        if (!SharesWork(argc, argv)) return EXIT_SUCCESS;  // rank 0 runs it alone
        quiet.emplace();
    }
    // Named, so that the help says "Usage: strata ..." however the program was started (the man
    // pages are made from it: tools/strata/HelpPages.py).
    CLI::App app{"strata: a GPU-free voxel database for LiDAR maps", "strata"};
    app.require_subcommand(1);
    app.set_version_flag("--version", strata::tools::VersionText());
    strata::tools::RegisterIntegrate(app);
    strata::tools::RegisterInfo(app);
    strata::tools::RegisterExport(app);
    strata::tools::RegisterSession(app);
    strata::tools::RegisterMaintenance(app);
    strata::tools::RegisterDiff(app);
    strata::tools::RegisterWalls(app);
    strata::tools::RegisterVehicles(app);
    strata::tools::RegisterDynamic(app);
    strata::tools::RegisterRegister(app);
    strata::tools::RegisterFloors(app);
    strata::tools::RegisterBag(app);
    strata::tools::RegisterOdometry(app);
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

}  // namespace

const strata::pipeline::Ranks& strata::tools::CommandRanks() { return *g_ranks; }

int main(int argc, char** argv) {
    KeepFreedMemory();
    try {
        // MPI (under mpirun) is finalised when `ranks` goes, after the command.
        const strata::pipeline::Ranks ranks =
            strata::pipeline::Ranks::FromEnvironment(&argc, &argv);
        return RunCommand(argc, argv, ranks);
    } catch (const std::exception& e) {
        std::cerr << "strata: error: " << e.what() << "\n";
        return ExitCodeOf(e);
    }
}
