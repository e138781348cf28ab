# Vehicle pipeline: accuracy on the simulated garage and time on real maps (docs/vehicles.md).
add_executable(bench_vehicles ${CMAKE_CURRENT_LIST_DIR}/bench_vehicles.cpp)
target_link_libraries(bench_vehicles PRIVATE strata_parking_eval Strata::vehicles
                      Strata::integration Strata::io TBB::tbb)
strata_use_build_paths(bench_vehicles)
strata_set_warnings(bench_vehicles)
