# Change query time over a BALM-sized map (docs/bench.md, Change detection).
add_executable(bench_change ${CMAKE_CURRENT_LIST_DIR}/bench_change.cpp)
target_link_libraries(bench_change PRIVATE Strata::change Strata::store Strata::io)
strata_use_build_paths(bench_change)
strata_set_warnings(bench_change)
