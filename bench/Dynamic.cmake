# Dynamic-object removal: SA / DA / AA on simulated traffic, the raw map beside the static map,
# and the time (docs/dynamic.md).
add_executable(bench_dynamic ${CMAKE_CURRENT_LIST_DIR}/bench_dynamic.cpp
                             ${CMAKE_CURRENT_LIST_DIR}/TrafficVehicles.cpp)
target_link_libraries(bench_dynamic PRIVATE Strata::pipeline Strata::dynamic Strata::sim
                      Strata::vehicles strata_parking_eval TBB::tbb)
target_include_directories(bench_dynamic PRIVATE ${PROJECT_SOURCE_DIR}/tests/support)
strata_use_build_paths(bench_dynamic)
strata_set_warnings(bench_dynamic)
# The figures docs/dynamic.md states, in CI (about 15 s): exits 1 on a miss, 77 without BALM.
add_test(NAME bench_dynamic.Targets COMMAND bench_dynamic)
set_tests_properties(bench_dynamic.Targets PROPERTIES LABELS bench SKIP_RETURN_CODE 77 TIMEOUT 600)
