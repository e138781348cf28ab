# Registration time and accuracy on real maps and the simulated building, one core
# (docs/registration.md).
add_executable(bench_registration ${CMAKE_CURRENT_LIST_DIR}/bench_registration.cpp
                                  ${CMAKE_CURRENT_LIST_DIR}/RegistrationPairs.cpp)
target_link_libraries(bench_registration PRIVATE Strata::registration Strata::integration
                                                 Strata::io Strata::sim TBB::tbb
                                                 strata_registration_reference)
strata_use_build_paths(bench_registration)
strata_set_warnings(bench_registration)
