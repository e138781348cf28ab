# Simulator throughput: rays per second per core on the example street (docs/simulator.md).
add_executable(bench_sim ${CMAKE_CURRENT_LIST_DIR}/bench_sim.cpp)
target_link_libraries(bench_sim PRIVATE Strata::sim benchmark::benchmark)
strata_use_build_paths(bench_sim)
strata_set_warnings(bench_sim)
# The district (docs/bench.md, "District"): simulates and integrates about 1 km^2 through the
# strata program; minutes, so a plain program run by hand, not a Google Benchmark.
add_executable(bench_district ${CMAKE_CURRENT_LIST_DIR}/bench_district.cpp)
target_link_libraries(bench_district PRIVATE nlohmann_json::nlohmann_json)
strata_use_build_paths(bench_district)
strata_set_warnings(bench_district)
if(TARGET strata)
  add_dependencies(bench_district strata)
endif()
# --scale runs `mpirun -n 1|2 strata integrate` (empty without Open MPI: --scale then refuses).
target_compile_definitions(bench_district PRIVATE STRATA_MPIEXEC="$<$<BOOL:${MPIEXEC_EXECUTABLE}>:${MPIEXEC_EXECUTABLE}>")
