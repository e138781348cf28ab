# Read by ctest after the test lists gtest_discover_tests writes (TEST_INCLUDE_FILES, appended
# in tests/CMakeLists.txt): the store's fault tests that kill processes at chosen moments or run
# reader processes against a writer must not have their timing depend on heavy tests running
# beside them under `ctest -j`. They run alone (RUN_SERIAL); the other fault tests (full disk,
# damaged files, locks) do not depend on timing and run beside the rest.
foreach(test IN LISTS test_cli_TESTS)
  if(test MATCHES "^(StoreFaults|StoreKills)\\.(Killed|ReaderProcesses)")
    set_tests_properties(${test} PROPERTIES RUN_SERIAL ON)
  endif()
endforeach()
