# Reading ROS 1 bags and integrating from them against KITTI folders (docs/bench.md, Recordings).
add_executable(bench_recordings ${CMAKE_CURRENT_LIST_DIR}/bench_recordings.cpp)
target_link_libraries(bench_recordings PRIVATE Strata::recordings Strata::pipeline TBB::tbb)
strata_use_build_paths(bench_recordings)
strata_set_warnings(bench_recordings)
# The short run in CI (--ci): the read speeds, streaming memory and --bag against --kitti held;
# without the real data it exits 77, a skip (a failure under STRATA_REQUIRE_DATA=1).
add_test(NAME BenchRecordingsCi COMMAND bench_recordings --ci)
set_tests_properties(BenchRecordingsCi PROPERTIES LABELS bench SKIP_RETURN_CODE 77 COST 30)
