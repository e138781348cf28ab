# strata_add_module(NAME <name> SOURCES <files...> PUBLIC_LINKS <...> PRIVATE_LINKS <...>)
# One stage = one folder = one namespace = one library target strata_<name>, alias Strata::<name>.
function(strata_add_module)
  cmake_parse_arguments(ARG "" "NAME" "SOURCES;PUBLIC_LINKS;PRIVATE_LINKS" ${ARGN})
  set(target strata_${ARG_NAME})
  add_library(${target} ${ARG_SOURCES})
  add_library(Strata::${ARG_NAME} ALIAS ${target})
  set_property(GLOBAL APPEND PROPERTY STRATA_MODULE_TARGETS ${target})  # cmake/Install.cmake
  target_compile_features(${target} PUBLIC cxx_std_17)
  target_include_directories(${target}
    PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include> $<INSTALL_INTERFACE:include>
    PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})  # its own private headers, no other module's
  target_link_libraries(${target} PUBLIC ${ARG_PUBLIC_LINKS} PRIVATE ${ARG_PRIVATE_LINKS})
  set_target_properties(${target} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  strata_set_warnings(${target})
  strata_pch(${target} library)
  strata_unity(${target})
endfunction()

# strata_test_program(<target>): what every test program shares. Its own sources compile at -O1
# whatever the build type: they are test bodies and comparisons, not the code under test (the
# libraries and tests/support keep the build type's -O3 or -O2), and at -O1 g++ and clang spend
# about half the time on them (test_store's batch: 63 s at -O3, 31 s at -O1;
# docs/reliability.md, "Build and CI time"). Debug builds keep -O0. Linked from another build's
# objects (cmake/TestObjects.cmake) it compiles nothing here: only its links matter.
function(strata_test_program target)
  strata_use_build_paths(${target})  # STRATA_DATA_DIR, STRATA_SOURCE_DIR, STRATA_BINARY
  if(STRATA_TEST_OBJECTS_FROM)
    return()
  endif()
  target_include_directories(${target} PRIVATE ${PROJECT_SOURCE_DIR}/tests/support)
  target_compile_options(${target} PRIVATE $<$<NOT:$<CONFIG:Debug>>:-O1>)
  strata_set_warnings(${target})
  strata_pch(${target} test)
endfunction()

# strata_add_gtest(<name> <sources...> LINKS <targets...> [TSAN_SOURCES <sources...>]): one test
# binary, discovered by CTest. TSAN_SOURCES: the files that hold the tests tools/sanitize.sh tsan
# runs; the ThreadSanitizer build (STRATA_SANITIZE=thread) compiles only those, not the program's
# simulated and real-data tests that it never runs (docs/reliability.md, "Sanitizers").
function(strata_add_gtest name)
  cmake_parse_arguments(ARG "" "" "LINKS;TSAN_SOURCES" ${ARGN})
  set(sources ${ARG_UNPARSED_ARGUMENTS})
  if(STRATA_SANITIZE STREQUAL "thread" AND ARG_TSAN_SOURCES)
    set(sources ${ARG_TSAN_SOURCES})
  endif()
  strata_test_executable(${name} ${sources})
  target_link_libraries(${name} PRIVATE ${ARG_LINKS} GTest::gtest GTest::gtest_main)
  strata_test_program(${name})
  strata_unity(${name})
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60 PROPERTIES TIMEOUT 600)
endfunction()
