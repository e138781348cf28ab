#pragma once
// One session being written into a map, scan by scan: `strata integrate` (IntegrateSession) and
// Python's `Map.session` both write through it.

#include <memory>

#include "strata/core/Scan.hpp"
#include "strata/integration/Integrator.hpp"
#include "strata/store/SessionWriter.hpp"

namespace strata::pipeline {

/// @brief A session in progress: Integrate adds scans, Commit records them all in one
/// transaction. Destroyed without a Commit, it removes what it wrote: the map on disk stays as it
/// was. Not thread-safe (one writer per map).
class NewSession {
public:
    /// @throw InvalidArgumentError when `map` is not open for writing, `rule` is invalid or
    /// differs from the map's recorded rule.
    NewSession(store::MapStore& map, const integration::IntegrationConfig& rule,
               store::SessionOptions options);

    /// @brief Integrates the next scan. An integration error (a refused scan, a bad pose) is
    /// rethrown as the same kind, its message prefixed with "scan <i> (<scan.source>): ".
    integration::ScanUpdate Integrate(const core::Scan& scan);
    /// @brief Writes and records the session; the session takes no scan afterwards.
    /// @throw InvalidArgumentError when committed already.
    store::SessionRecord Commit();

    [[nodiscard]] size_t scans() const { return scans_; }
    [[nodiscard]] bool committed() const { return committed_; }
    [[nodiscard]] const store::WriterStats& stats() const { return writer_->stats(); }

private:
    std::unique_ptr<store::SessionWriter> writer_;  // movable session, fixed writer
    size_t scans_ = 0;
    bool committed_ = false;
};

}  // namespace strata::pipeline
