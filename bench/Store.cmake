# Store overhead over in-memory integration, memory budget, one-tile reads, sessions 1..50,
# reads by kind, format-4 migration (docs/bench.md, Store).
add_executable(bench_store ${CMAKE_CURRENT_LIST_DIR}/bench_store.cpp
  ${CMAKE_CURRENT_LIST_DIR}/StoreSessions.cpp)
target_link_libraries(bench_store PRIVATE Strata::store Strata::io strata_test_support
  strata_format4_map TBB::tbb SQLite::SQLite3 PkgConfig::XXHASH)
strata_use_build_paths(bench_store)
strata_set_warnings(bench_store)
# The short run checks the targets in CI (about 1-2 minutes on 2 cores); the full run writes
# docs/bench.md (bench/run_benchmarks.sh). Without BALM or KITTI 00 it exits 77, a skip (a
# failure under STRATA_REQUIRE_DATA=1).
if(STRATA_BUILD_TESTS)
  add_test(NAME bench_store_short COMMAND bench_store --short)
  set_tests_properties(bench_store_short PROPERTIES RUN_SERIAL TRUE TIMEOUT 900 LABELS bench
                       SKIP_RETURN_CODE 77
                       COST 18)  # seconds on 2026-12-04 (tests/TestCosts.cmake)
endif()
