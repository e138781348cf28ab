#pragma once
// Where the tests, benchmarks and the fuzz corpus generator find the source tree, the real data
// and the programs they run. Force-included (cmake/BuildPaths.cmake); the paths are compiled once
// per build directory into strata_build_paths, not written into every object file's command
// line, so that ccache shares the objects between clones in different folders.

namespace strata::build_paths {
[[nodiscard]] const char* SourceDir();  ///< the project root
[[nodiscard]] const char* DataDir();    ///< STRATA_DATA_DIR (../shared/data by default)
[[nodiscard]] const char* Binary();     ///< the `strata` program ("" when not built)
[[nodiscard]] const char* EioShim();    ///< tests/tools/EioShim.cpp's library ("" when not built)
}  // namespace strata::build_paths

// A target that still defines one of them with -D keeps its own (and its objects' command lines
// then hold the path again).
#ifndef STRATA_SOURCE_DIR
#define STRATA_SOURCE_DIR (::strata::build_paths::SourceDir())
#endif
#ifndef STRATA_DATA_DIR
#define STRATA_DATA_DIR (::strata::build_paths::DataDir())
#endif
#ifndef STRATA_BINARY
#define STRATA_BINARY (::strata::build_paths::Binary())
#endif
#ifndef STRATA_EIO_SHIM
#define STRATA_EIO_SHIM (::strata::build_paths::EioShim())
#endif
