#pragma once

namespace strata::tools {

/// @brief What `strata --version` prints: "strata <version> (<git commit>)", the commit
/// "unknown" when the program was built outside a git checkout. Defined in a file generated at
/// build time (cmake/VersionStamp.cmake), so that a new commit recompiles only that file.
[[nodiscard]] const char* VersionText();

}  // namespace strata::tools
