# Read by ctest after the test lists gtest_discover_tests writes (TEST_INCLUDE_FILES, appended
# in tests/CMakeLists.txt): the store's fault tests kill processes at chosen moments and run
# reader processes against a writer, so their timing must not depend on heavy tests running
# beside them under `ctest -j`. They run alone (RUN_SERIAL).
foreach(test IN LISTS test_cli_TESTS)
  if(test MATCHES "^(StoreFaults|StoreKills)\\.")
    set_tests_properties(${test} PROPERTIES RUN_SERIAL ON)
  endif()
endforeach()
