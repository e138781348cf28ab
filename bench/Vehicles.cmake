# Vehicle pipeline: accuracy on the simulated garage and time on real maps (docs/vehicles.md).
add_executable(bench_vehicles ${CMAKE_CURRENT_LIST_DIR}/bench_vehicles.cpp)
target_link_libraries(bench_vehicles PRIVATE strata_parking_eval Strata::vehicles
                      Strata::integration Strata::io TBB::tbb)
strata_use_build_paths(bench_vehicles)
strata_set_warnings(bench_vehicles)
# The accuracy targets in CI (about 75 s): the program exits 1 on a miss.
add_test(NAME bench_vehicles.AccuracyTargets COMMAND bench_vehicles --accuracy-only)
set_tests_properties(bench_vehicles.AccuracyTargets PROPERTIES LABELS bench TIMEOUT 900
                     COST 60)  # seconds on 2026-12-04 (tests/TestCosts.cmake)
