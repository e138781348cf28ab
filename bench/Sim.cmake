# Simulator throughput: rays per second per core on the example street (docs/simulator.md).
add_executable(bench_sim ${CMAKE_CURRENT_LIST_DIR}/bench_sim.cpp)
target_link_libraries(bench_sim PRIVATE Strata::sim benchmark::benchmark)
strata_use_build_paths(bench_sim)
strata_set_warnings(bench_sim)
