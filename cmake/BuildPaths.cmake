# Tests, benchmarks and the fuzz corpus generator need absolute paths: the source tree, the real
# data, the `strata` program. As -D definitions they would put the clone's folder on every
# object's command line, which ccache hashes: no object would be shared between clones. Instead
# one generated file per build directory holds them (strata_build_paths) and
# tests/support/BuildPaths.hpp, force-included, turns STRATA_SOURCE_DIR, STRATA_DATA_DIR,
# STRATA_BINARY and STRATA_EIO_SHIM into calls to it.
set(_strata_paths_cpp ${PROJECT_BINARY_DIR}/generated/BuildPaths.cpp)
string(CONFIGURE [[
#include "BuildPaths.hpp"

namespace strata::build_paths {
const char* SourceDir() { return R"strata(@PROJECT_SOURCE_DIR@)strata"; }
const char* DataDir() { return R"strata(@STRATA_DATA_DIR@)strata"; }
const char* Binary() { return R"strata($<$<TARGET_EXISTS:strata>:$<TARGET_FILE:strata>>)strata"; }
const char* EioShim() {
    return R"strata($<$<TARGET_EXISTS:strata_eio_shim>:$<TARGET_FILE:strata_eio_shim>>)strata";
}
}  // namespace strata::build_paths
]] _strata_paths_content @ONLY)
file(GENERATE OUTPUT ${_strata_paths_cpp} CONTENT "${_strata_paths_content}")
add_library(strata_build_paths STATIC ${_strata_paths_cpp})
target_include_directories(strata_build_paths PUBLIC ${PROJECT_SOURCE_DIR}/tests/support)
target_compile_features(strata_build_paths PUBLIC cxx_std_17)

# strata_use_build_paths(<target>): STRATA_SOURCE_DIR and friends in every source of <target>.
function(strata_use_build_paths target)
  target_link_libraries(${target} PRIVATE strata_build_paths)
  target_compile_options(${target} PRIVATE
    "SHELL:-include ${PROJECT_SOURCE_DIR}/tests/support/BuildPaths.hpp")
endfunction()
