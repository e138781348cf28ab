# All dependencies come from Debian 12 packages (tools/setup.sh installs them); nothing is downloaded.
# Order matters: TBB and Ceres must be found before OpenVDB, or CMake fails with
# "Some (but not all) targets in this export set were already defined".
find_package(TBB CONFIG REQUIRED)
find_package(Ceres REQUIRED)
list(APPEND CMAKE_MODULE_PATH /usr/lib/x86_64-linux-gnu/cmake/OpenVDB)
find_package(OpenVDB REQUIRED)
find_package(Eigen3 3.3 CONFIG REQUIRED NO_MODULE)
find_package(embree 3 REQUIRED)
find_package(octomap REQUIRED)
find_package(liblzf CONFIG REQUIRED)
find_package(SQLite3 REQUIRED)
find_package(PNG REQUIRED)
find_package(BZip2 REQUIRED)
find_package(CLI11 CONFIG REQUIRED)
find_package(nlohmann_json 3 CONFIG REQUIRED)
find_package(PkgConfig REQUIRED)
pkg_check_modules(XXHASH REQUIRED IMPORTED_TARGET libxxhash)
pkg_check_modules(LZ4 REQUIRED IMPORTED_TARGET liblz4)    # lz4 chunks of ROS 1 bags and MCAP
pkg_check_modules(ZSTD REQUIRED IMPORTED_TARGET libzstd)  # zstd chunks of MCAP
find_package(ZLIB REQUIRED)                               # MCAP's CRC-32
# Open MPI (libopenmpi-dev) for `mpirun strata ...`; without it strata runs as one process.
find_package(MPI COMPONENTS CXX QUIET)
if(MPI_CXX_FOUND)
  set(STRATA_WITH_MPI ON)
else()
  set(STRATA_WITH_MPI OFF)
  message(STATUS "MPI not found: strata runs as one process only (tools/setup.sh installs it)")
endif()
if(STRATA_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(STRATA_BUILD_BENCH)
  find_package(benchmark QUIET)
endif()

# octomap's config exports plain target names; give them one include-carrying alias.
if(NOT TARGET Strata::octomap)
  add_library(strata_octomap_dep INTERFACE)
  target_include_directories(strata_octomap_dep SYSTEM INTERFACE ${OCTOMAP_INCLUDE_DIRS})
  target_link_libraries(strata_octomap_dep INTERFACE ${OCTOMAP_LIBRARIES})
  add_library(Strata::octomap ALIAS strata_octomap_dep)
endif()
