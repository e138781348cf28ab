# Reading ROS 1 bags and integrating from them against KITTI folders (docs/bench.md, Recordings).
add_executable(bench_recordings ${CMAKE_CURRENT_LIST_DIR}/bench_recordings.cpp)
target_link_libraries(bench_recordings PRIVATE Strata::recordings Strata::pipeline TBB::tbb)
strata_use_build_paths(bench_recordings)
strata_set_warnings(bench_recordings)
