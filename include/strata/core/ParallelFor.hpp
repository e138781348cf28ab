#pragma once
// A parallel loop whose failures do not cancel the other iterations.
// A throw inside tbb::parallel_for cancels the task group, and with it the parallel work OpenVDB
// runs inside the other iterations (topology unions, leaf loops), which OpenVDB does not expect:
// a tree left half-built crashed when it was destroyed. Here every iteration runs to its end
// and the first failure is rethrown once all have.

#include <tbb/parallel_for.h>

#include <exception>
#include <mutex>

namespace strata::core {

/// @brief Calls body(i) for i in [0, n) in parallel (TBB); every call runs to its end, then the
/// first exception thrown, if any, is rethrown.
template <typename Body>
void ParallelFor(size_t n, const Body& body) {
    std::exception_ptr first;
    std::mutex mutex;
    tbb::parallel_for(size_t{0}, n, [&](size_t i) {
        try {
            body(i);
        } catch (...) {
            const std::lock_guard<std::mutex> lock(mutex);
            if (!first) first = std::current_exception();
        }
    });
    if (first) std::rethrow_exception(first);
}

}  // namespace strata::core
