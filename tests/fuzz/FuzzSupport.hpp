#pragma once

// Shared by the libFuzzer targets (docs/reliability.md, Fuzzing): readers take paths, so each
// input is written to a file in a per-process scratch folder before the reader opens it.

#include <cstddef>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <string>

#include "strata/core/Error.hpp"
#include "strata/core/Scan.hpp"

namespace strata::fuzz {

/// @brief A folder private to this process (under /dev/shm when it exists, so inputs never
/// touch a disk), created on first use and removed when the process exits normally.
[[nodiscard]] const std::filesystem::path& ScratchDir();

/// @brief Writes the input to ScratchDir() / name and returns the path.
std::filesystem::path WriteInput(const uint8_t* data, size_t size, const std::string& name);

/// @brief Replaces `path` with `size` bytes; throws std::logic_error (a harness failure, not a
/// finding) when it cannot.
void WriteBytes(const std::filesystem::path& path, const char* data, size_t size);

/// @brief Aborts (a finding) on an exception that is not an accepted refusal: anything but a
/// std::runtime_error or std::invalid_argument of exactly that type, the kinds the library's
/// older code still throws until they become strata::Error kinds (docs/architecture.md,
/// "Errors"); those too with STRATA_FUZZ_STRICT_KINDS=1.
void RejectUnexpected(const std::exception& e);

/// @brief Runs fn: a strata::Error means the reader refused the file, which is the accepted
/// outcome for a malformed one. Any other exception (std::out_of_range, std::logic_error,
/// std::bad_alloc, an OpenVDB exception: see RejectUnexpected), a crash, a sanitizer report, a
/// hang or running out of memory is a bug for libFuzzer.
template <typename Fn>
void Refusal(Fn fn) {
    try {
        fn();
    } catch (const Error&) {
    } catch (const std::exception& e) {
        RejectUnexpected(e);
    }
}

/// @brief Aborts (a finding for libFuzzer) with `what` when a reader's result breaks its
/// documented contract: a file it accepted must not hand the map inconsistent data.
void Expect(bool ok, const char* what);

/// @brief The contract of ReadPointCloud's result: attribute arrays one-to-one with the points,
/// a finite pose, and (`finite_points`) no non-finite point.
void ExpectValidScan(const core::Scan& scan, bool finite_points);

}  // namespace strata::fuzz
