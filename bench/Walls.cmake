# Wall pipeline time on real maps, one core (docs/bench.md, Walls).
add_executable(bench_walls ${CMAKE_CURRENT_LIST_DIR}/bench_walls.cpp)
target_link_libraries(bench_walls PRIVATE Strata::walls Strata::integration Strata::io TBB::tbb)
target_compile_definitions(bench_walls PRIVATE STRATA_DATA_DIR="${STRATA_DATA_DIR}")
strata_set_warnings(bench_walls)
