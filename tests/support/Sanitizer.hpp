#pragma once
// Whether the test runs in a sanitizer build: tools/sanitize.sh sets STRATA_SANITIZER (address or
// thread). Instrumented code runs 5-15 times slower, so a test that repeats the same calls over
// many cases runs fewer of them there; the normal build runs them all (docs/reliability.md,
// "Sanitizers").
#include <cstdlib>

namespace strata::testing {

[[nodiscard]] inline bool UnderSanitizer() {
    const char* env = std::getenv("STRATA_SANITIZER");
    return env != nullptr && *env != '\0';
}

}  // namespace strata::testing
