#pragma once
// Real data (../shared/data) is optional on a developer's machine and required in CI. CTest counts
// a skipped test as passed, so with STRATA_REQUIRE_DATA=1 (set by .ci/run) a test whose data is
// missing fails instead of skipping: the suite cannot shrink silently.

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>

namespace strata::test {

/// @brief True when STRATA_REQUIRE_DATA=1: missing real data is a failure.
[[nodiscard]] inline bool RealDataRequired() {
    const char* v = std::getenv("STRATA_REQUIRE_DATA");
    return v != nullptr && std::strcmp(v, "1") == 0;
}

}  // namespace strata::test

/// Skips the calling test when `data_path` does not exist, or fails it under STRATA_REQUIRE_DATA=1.
#define STRATA_SKIP_WITHOUT_DATA(data_path)                                         \
    do {                                                                            \
        const std::filesystem::path strata_data_path_(data_path);                   \
        if (!std::filesystem::exists(strata_data_path_)) {                          \
            if (::strata::test::RealDataRequired()) {                               \
                FAIL() << "real data not found: " << strata_data_path_              \
                       << " (STRATA_REQUIRE_DATA=1; see ../shared/data/README.md)"; \
            }                                                                       \
            GTEST_SKIP() << "real data not found: " << strata_data_path_            \
                         << " (see ../shared/data/README.md)";                      \
        }                                                                           \
    } while (false)
