# Store overhead over in-memory integration, memory budget, one-tile reads (docs/bench.md, Store).
add_executable(bench_store ${CMAKE_CURRENT_LIST_DIR}/bench_store.cpp)
target_link_libraries(bench_store PRIVATE Strata::store Strata::io strata_test_support TBB::tbb)
strata_use_build_paths(bench_store)
strata_set_warnings(bench_store)
