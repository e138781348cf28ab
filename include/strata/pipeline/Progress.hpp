#pragma once
// How a long use case tells its caller how far it is: a callback in its options. The library
// never draws anything; the `strata` program turns the events into its progress bar.

#include <cstddef>
#include <functional>
#include <string>

namespace strata::pipeline {

/// @brief One step of work done: `done` of `total` items of the stage named `stage` ("reading
/// scans", "integrating"). Each stage starts with done = 0.
struct ProgressEvent {
    std::string stage;
    size_t done = 0;
    size_t total = 0;
};

/// @brief Called from the thread that runs the use case; empty: no reports.
using ProgressCallback = std::function<void(const ProgressEvent&)>;

/// @brief Calls `callback` (when set) with one event.
inline void ReportProgress(const ProgressCallback& callback, const std::string& stage, size_t done,
                           size_t total) {
    if (callback) callback(ProgressEvent{stage, done, total});
}

}  // namespace strata::pipeline
