# LiDAR odometry's speed per sweep on the simulated district drive and KITTI 00 (docs/bench.md,
# Odometry). CTest runs it (a miss of the 50 ms target fails; 77 without the real data).
add_executable(bench_odometry ${CMAKE_CURRENT_LIST_DIR}/bench_odometry.cpp)
target_link_libraries(bench_odometry PRIVATE Strata::registration Strata::io strata_simulated_drive
                                             TBB::tbb)
strata_use_build_paths(bench_odometry)
strata_set_warnings(bench_odometry)
add_test(NAME BenchOdometryCi COMMAND bench_odometry)
set_tests_properties(BenchOdometryCi PROPERTIES LABELS bench SKIP_RETURN_CODE 77 COST 15)
