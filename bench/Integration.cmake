add_executable(bench_integration bench_integration.cpp)
target_link_libraries(bench_integration PRIVATE Strata::integration Strata::io strata_test_support
                                                TBB::tbb)
strata_use_build_paths(bench_integration)
strata_set_warnings(bench_integration)
if(TARGET strata)  # the whole command's rows run `strata integrate`
  add_dependencies(bench_integration strata)
endif()
# The short run in CI: fails when a voxel differs from OctoMap's or a ratio misses its floor.
# Without the real data it exits 77, a skip (a failure under STRATA_REQUIRE_DATA=1).
add_test(NAME BenchIntegrationCi COMMAND bench_integration --ci)
set_tests_properties(BenchIntegrationCi PROPERTIES LABELS bench SKIP_RETURN_CODE 77
                     COST 25)  # seconds expected quiet since the 0.1 m rows (tests/TestCosts.cmake)
