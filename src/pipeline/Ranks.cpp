#include "strata/pipeline/Ranks.hpp"

#include <algorithm>
#include <chrono>
#include <climits>
#include <cstdlib>
#include <numeric>
#include <thread>

#include "strata/core/Error.hpp"

#ifdef STRATA_WITH_MPI
#include <mpi.h>
#endif

namespace strata::pipeline {
namespace {

// Set by Open MPI's launcher (and by MPICH's and Slurm's as PMI_SIZE / PMIX_RANK).
int LaunchedRanks() {
    for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"}) {
        if (const char* v = std::getenv(name)) return std::max(1, std::atoi(v));
    }
    return std::getenv("PMIX_RANK") ? 2 : 1;  // a PMIx launch of unknown size
}

}  // namespace

#ifdef STRATA_WITH_MPI

namespace {

// Returns once every rank has called it, sleeping between looks instead of polling. Open MPI's
// blocking calls wait in a busy loop: a rank waiting for rank 0 (its commit, the odometry's
// poses, the last rank's share) would hold a core the working ranks need, on a machine with
// fewer cores than ranks, and burn it on any. Each exchange below starts here, so its own
// blocking call finds every rank present and spins only while the bytes move. The pause grows
// to 1 ms: at most that late, about a thousand cheap looks a second while a rank waits.
void AwaitEveryRank() {
    MPI_Request request = MPI_REQUEST_NULL;
    MPI_Ibarrier(MPI_COMM_WORLD, &request);
    auto pause = std::chrono::microseconds(20);
    for (int done = 0;;) {
        MPI_Test(&request, &done, MPI_STATUS_IGNORE);
        if (done != 0) return;
        std::this_thread::sleep_for(pause);
        pause = std::min(2 * pause, std::chrono::microseconds(1000));
    }
}

}  // namespace

struct Ranks::Mpi {
    Mpi(int* argc, char*** argv) { MPI_Init(argc, argv); }
    ~Mpi() {
        AwaitEveryRank();  // MPI_Finalize waits for the others in a busy loop too
        MPI_Finalize();
    }
    Mpi(const Mpi&) = delete;
    Mpi& operator=(const Mpi&) = delete;
};

namespace {

int MessageBytes(size_t bytes) {
    if (bytes > static_cast<size_t>(INT_MAX)) {
        throw InvalidArgumentError("one message between ranks would exceed 2 GB");
    }
    return static_cast<int>(bytes);
}

std::vector<int> Displacements(const std::vector<int>& counts) {
    std::vector<int> offsets(counts.size(), 0);
    for (size_t i = 1; i < counts.size(); ++i) offsets[i] = offsets[i - 1] + counts[i - 1];
    return offsets;
}

std::vector<std::string> SplitMessages(const std::string& all, const std::vector<int>& counts) {
    std::vector<std::string> out;
    size_t at = 0;
    for (int c : counts) {
        out.push_back(all.substr(at, static_cast<size_t>(c)));
        at += static_cast<size_t>(c);
    }
    return out;
}

}  // namespace

Ranks Ranks::FromEnvironment(int* argc, char*** argv) {
    Ranks ranks;
    if (LaunchedRanks() <= 1 && !std::getenv("OMPI_COMM_WORLD_RANK")) return ranks;
    ranks.mpi_ = std::make_shared<Mpi>(argc, argv);
    MPI_Comm_rank(MPI_COMM_WORLD, &ranks.rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks.size_);
    return ranks;
}

std::vector<std::string> Ranks::Exchange(const std::vector<std::string>& out) const {
    if (out.size() != static_cast<size_t>(size_)) {
        throw InvalidArgumentError("Exchange needs one message per rank");
    }
    if (!mpi_) return out;
    std::vector<int> send_counts(out.size()), recv_counts(out.size());
    std::string send;
    for (size_t r = 0; r < out.size(); ++r) {
        send_counts[r] = MessageBytes(out[r].size());
        send += out[r];
    }
    AwaitEveryRank();
    MPI_Alltoall(send_counts.data(), 1, MPI_INT, recv_counts.data(), 1, MPI_INT, MPI_COMM_WORLD);
    const size_t total = std::accumulate(recv_counts.begin(), recv_counts.end(), size_t{0});
    std::string recv(total, '\0');
    const std::vector<int> send_offsets = Displacements(send_counts),
                           recv_offsets = Displacements(recv_counts);
    (void)MessageBytes(send.size());
    (void)MessageBytes(total);
    MPI_Alltoallv(send.data(), send_counts.data(), send_offsets.data(), MPI_CHAR, recv.data(),
                  recv_counts.data(), recv_offsets.data(), MPI_CHAR, MPI_COMM_WORLD);
    return SplitMessages(recv, recv_counts);
}

std::vector<std::string> Ranks::Gather(const std::string& bytes) const {
    if (!mpi_) return {bytes};
    int count = MessageBytes(bytes.size());
    std::vector<int> counts(root() ? static_cast<size_t>(size_) : 0);
    AwaitEveryRank();
    MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
    const std::vector<int> offsets = Displacements(counts);
    std::string all(root() ? std::accumulate(counts.begin(), counts.end(), size_t{0}) : 0, '\0');
    MPI_Gatherv(bytes.data(), count, MPI_CHAR, all.data(), counts.data(), offsets.data(), MPI_CHAR,
                0, MPI_COMM_WORLD);
    return root() ? SplitMessages(all, counts) : std::vector<std::string>{};
}

std::string Ranks::Broadcast(const std::string& bytes) const {
    if (!mpi_) return bytes;
    int count = root() ? MessageBytes(bytes.size()) : 0;
    AwaitEveryRank();
    MPI_Bcast(&count, 1, MPI_INT, 0, MPI_COMM_WORLD);
    std::string out = root() ? bytes : std::string(static_cast<size_t>(count), '\0');
    MPI_Bcast(out.data(), count, MPI_CHAR, 0, MPI_COMM_WORLD);
    return out;
}

bool Ranks::AllOk(bool ok) const {
    if (!mpi_) return ok;
    int mine = ok ? 1 : 0, all = 0;
    AwaitEveryRank();
    MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    return all == 1;
}

#else  // built without MPI: one process only

struct Ranks::Mpi {};

Ranks Ranks::FromEnvironment(int*, char***) {
    if (LaunchedRanks() > 1) {
        throw InvalidArgumentError(
            "started by mpirun with several ranks, but this strata was built without MPI "
            "(install libopenmpi-dev and rebuild, or run one process)");
    }
    return Ranks();
}

std::vector<std::string> Ranks::Exchange(const std::vector<std::string>& out) const {
    if (out.size() != 1) throw InvalidArgumentError("Exchange needs one message per rank");
    return out;
}
std::vector<std::string> Ranks::Gather(const std::string& bytes) const { return {bytes}; }
std::string Ranks::Broadcast(const std::string& bytes) const { return bytes; }
bool Ranks::AllOk(bool ok) const { return ok; }

#endif

Ranks::Ranks() = default;

}  // namespace strata::pipeline
