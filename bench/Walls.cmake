# Wall pipeline time on real maps, one core (docs/bench.md, Walls).
add_executable(bench_walls ${CMAKE_CURRENT_LIST_DIR}/bench_walls.cpp)
target_link_libraries(bench_walls PRIVATE Strata::walls Strata::integration Strata::io TBB::tbb)
strata_use_build_paths(bench_walls)
strata_set_warnings(bench_walls)
