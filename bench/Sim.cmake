# Simulator throughput: rays per second per core on the example street (docs/simulator.md).
add_executable(bench_sim ${CMAKE_CURRENT_LIST_DIR}/bench_sim.cpp)
target_link_libraries(bench_sim PRIVATE Strata::sim benchmark::benchmark)
target_compile_definitions(bench_sim PRIVATE STRATA_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
strata_set_warnings(bench_sim)
