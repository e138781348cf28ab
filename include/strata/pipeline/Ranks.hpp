#pragma once
// The processes one command runs on (docs/scale.md): this process alone, or the ranks `mpirun`
// started. The use cases talk to the other ranks through this class only, in bytes, so that
// nothing else in strata depends on MPI.

#include <memory>
#include <string>
#include <vector>

namespace strata::pipeline {

/// @brief This process's rank among the processes of one command, and the exchanges between
/// them. Every rank must make the same calls in the same order (MPI collectives). A rank that
/// dies ends the whole job (mpirun's default): no rank waits forever, no commit happens.
class Ranks {
public:
    /// One process: rank 0 of 1; every exchange is local.
    Ranks();
    /// The ranks of mpirun when this process was started by it (MPI is initialised here and
    /// finalised when the last copy is destroyed), else one process. MPI_Init is not called
    /// outside mpirun: it costs about a second.
    /// @throw InvalidArgumentError when started by mpirun with several ranks but built without
    /// MPI (each copy would write the map on its own).
    [[nodiscard]] static Ranks FromEnvironment(int* argc, char*** argv);

    [[nodiscard]] int rank() const { return rank_; }
    [[nodiscard]] int size() const { return size_; }
    [[nodiscard]] bool root() const { return rank_ == 0; }

    /// Sends `out[r]` to rank r, for every r (out.size() == size()); returns what each rank
    /// sent here, by sender.
    [[nodiscard]] std::vector<std::string> Exchange(const std::vector<std::string>& out) const;
    /// Rank 0 gets every rank's bytes, by rank; the others get nothing.
    [[nodiscard]] std::vector<std::string> Gather(const std::string& bytes) const;
    /// Every rank gets rank 0's bytes.
    [[nodiscard]] std::string Broadcast(const std::string& bytes) const;
    /// True on every rank when every rank passed true: how ranks agree that a step worked.
    [[nodiscard]] bool AllOk(bool ok) const;

private:
    struct Mpi;
    std::shared_ptr<Mpi> mpi_;  // null: one process
    int rank_ = 0;
    int size_ = 1;
};

}  // namespace strata::pipeline
