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
# docs/reliability.md, "Build and CI time"). Debug builds keep -O0.
function(strata_test_program target)
  strata_use_build_paths(${target})  # STRATA_DATA_DIR, STRATA_SOURCE_DIR, STRATA_BINARY
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
  strata_asan_ci_sources(sources ${sources})
  add_executable(${name} ${sources})
  target_link_libraries(${name} PRIVATE ${ARG_LINKS} GTest::gtest GTest::gtest_main)
  strata_test_program(${name})
  strata_unity(${name})
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60 PROPERTIES TIMEOUT 600)
endfunction()

# strata_asan_ci_sources(<out-var> <sources...>): the sources less, with STRATA_ASAN_CI_SELECTION
# (tools/sanitize.sh asan under .ci/run), every test file whose tests all match a line of
# tests/AsanSlowTests.txt, the tests CI's ASan run leaves out: the ASan build does not compile
# what that run never executes. A test is read from its `TEST(Suite, Name)` line (TEST_F alike; a
# TEST_P as `P/Suite.Name/0`, since CTest names it with a prefix and a suffix); a file with a test
# the lines do not match, or one written over two lines, is kept. A program left without test files
# is built from an empty one: it lists no tests, and targets that name it stay valid.
option(STRATA_ASAN_CI_SELECTION "Leave out test files whose every test CI's ASan run leaves out" OFF)
if(STRATA_ASAN_CI_SELECTION)
  file(STRINGS ${PROJECT_SOURCE_DIR}/tests/AsanSlowTests.txt _slow REGEX "^[^#]")
  list(JOIN _slow "|" STRATA_ASAN_SLOW_REGEX)
  file(WRITE ${PROJECT_BINARY_DIR}/generated/NoTests.cpp
       "// No test of this program runs in CI's ASan run (tests/AsanSlowTests.txt).\n")
  set_property(DIRECTORY ${PROJECT_SOURCE_DIR} APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS
               ${PROJECT_SOURCE_DIR}/tests/AsanSlowTests.txt)
endif()
function(strata_asan_ci_sources out)
  if(NOT STRATA_ASAN_CI_SELECTION)
    set(${out} ${ARGN} PARENT_SCOPE)
    return()
  endif()
  set(kept)
  foreach(source IN LISTS ARGN)
    set(tests)
    if(source MATCHES "\\.cpp$")
      cmake_path(ABSOLUTE_PATH source BASE_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR} OUTPUT_VARIABLE path)
      file(STRINGS ${path} tests REGEX "^TEST(_F|_P)?\\(")
    endif()
    set(slow_only FALSE)
    if(tests)
      set(slow_only TRUE)
    endif()
    foreach(test IN LISTS tests)
      set(test_name "")
      if(test MATCHES "^TEST(_F|_P)?\\(([A-Za-z0-9_]+), *([A-Za-z0-9_]+)\\)")
        set(test_name "${CMAKE_MATCH_2}.${CMAKE_MATCH_3}")
        if(CMAKE_MATCH_1 STREQUAL "_P")
          set(test_name "P/${test_name}/0")
        endif()
      endif()
      if(NOT test_name OR NOT test_name MATCHES "${STRATA_ASAN_SLOW_REGEX}")
        set(slow_only FALSE)
      endif()
    endforeach()
    if(NOT slow_only)
      list(APPEND kept ${source})
    endif()
  endforeach()
  if(NOT kept)
    set(kept ${PROJECT_BINARY_DIR}/generated/NoTests.cpp)
  endif()
  set(${out} ${kept} PARENT_SCOPE)
endfunction()
