# Registration time and accuracy on real maps and the simulated building, one core
# (docs/registration.md).
add_executable(bench_registration ${CMAKE_CURRENT_LIST_DIR}/bench_registration.cpp
                                  ${CMAKE_CURRENT_LIST_DIR}/RegistrationPairs.cpp)
target_link_libraries(bench_registration PRIVATE Strata::registration Strata::integration
                                                 Strata::io Strata::sim TBB::tbb
                                                 strata_registration_reference)
strata_use_build_paths(bench_registration)
strata_set_warnings(bench_registration)
# The accuracy of the first table in CI: the program exits 1 when a row errs by more than 2.5x
# what docs/registration.md measured. The real pairs' 0.05 deg target (the second table) is held
# in CI by the RegistrationRealData tests on the same pairs; the pairs and the localization time
# are checked by hand (without --accuracy-only). Without the real data it exits 77, a skip (a
# failure under STRATA_REQUIRE_DATA=1).
add_test(NAME bench_registration.AccuracyTargets
         COMMAND bench_registration --repeat 1 --accuracy-only)
set_tests_properties(bench_registration.AccuracyTargets PROPERTIES LABELS bench TIMEOUT 900
                     SKIP_RETURN_CODE 77
                     COST 10)  # seconds on 2026-12-07 (tests/TestCosts.cmake)
