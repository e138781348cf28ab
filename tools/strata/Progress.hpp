#pragma once

#include <chrono>
#include <cstddef>
#include <string>

#include "strata/pipeline/Progress.hpp"

namespace strata::tools {

/// A one-line progress bar on stderr, shown only when stderr is a terminal.
class Progress {
public:
    Progress(std::string label, size_t total);
    ~Progress();
    Progress(const Progress&) = delete;
    Progress& operator=(const Progress&) = delete;

    void Advance(size_t n = 1);
    /// For work whose total is known only as it runs.
    void Update(size_t done, size_t total);

private:
    void Draw() const;

    std::string label_;
    size_t total_;
    size_t done_ = 0;
    bool enabled_;
    std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

/// A pipeline use case's progress events drawn as bars: one per stage, ended when the stage is.
[[nodiscard]] pipeline::ProgressCallback ProgressBars();

}  // namespace strata::tools
