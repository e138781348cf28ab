# Test code compiled once for two builds (docs/reliability.md, "Sanitizers": "The tests' own
# code from the Release build").
#
# Every build lists the objects of each test program and test support library in
# test-objects/<target>.txt. A build configured with -DSTRATA_TEST_OBJECTS_FROM=<another build
# of this tree> does not compile those targets: it links them from that build's objects. CI's
# ASan + UBSan build does (tools/sanitize.sh asan with STRATA_ASAN_TEST_OBJECTS_FROM=build, set by
# .ci/run): it instruments the libraries, the `strata` program and the fuzz targets, and takes the
# tests' own code from the Release build, which compiled it minutes before (the test programs and
# support libraries were about 730 s of the ASan build's compile jobs in the cold run of
# 2026-12-07). What the tests call in the libraries is checked as before, and so is every heap
# block (ASan replaces the allocator of the whole process); the tests' own loops, fixtures and
# scoring run unchecked. g++'s and clang's objects link together: same standard library, same
# ABI, no -march (the ASan build already links Debian's g++-built OpenVDB, Ceres and GTest).
#
# In such a build the test-side targets are left out of `all` (their objects may not exist
# yet when it starts: .ci/run builds the sanitizer libraries while build/ compiles); the target
# `strata_test_code` builds them, in any build.
set(STRATA_TEST_OBJECTS_FROM "" CACHE PATH
    "Link the test programs from the objects of this other build of the tree (CI's ASan build)")

if(STRATA_TEST_OBJECTS_FROM)
  if(NOT EXISTS ${STRATA_TEST_OBJECTS_FROM}/CMakeCache.txt)
    message(FATAL_ERROR "STRATA_TEST_OBJECTS_FROM=${STRATA_TEST_OBJECTS_FROM} is not a configured "
                        "build directory (configure it first: tools/configure.sh makes build/)")
  endif()
  load_cache(${STRATA_TEST_OBJECTS_FROM} READ_WITH_PREFIX _from_ CMAKE_HOME_DIRECTORY)
  file(REAL_PATH "${_from_CMAKE_HOME_DIRECTORY}" _from_source)
  file(REAL_PATH "${PROJECT_SOURCE_DIR}" _our_source)
  if(NOT _from_source STREQUAL _our_source)
    message(FATAL_ERROR "STRATA_TEST_OBJECTS_FROM=${STRATA_TEST_OBJECTS_FROM} is a build of "
                        "${_from_CMAKE_HOME_DIRECTORY}, not of this tree (${PROJECT_SOURCE_DIR})")
  endif()
endif()

# strata_test_executable(<name> <sources...>), strata_test_library(<name> <sources...>): an
# executable or static library of test code, compiled from <sources> or, with
# STRATA_TEST_OBJECTS_FROM, linked from that build's objects of the target of the same name.
function(strata_test_executable name)
  _strata_test_sources(sources ${name} ${ARGN})
  add_executable(${name} ${sources})
  _strata_test_target(${name})
endfunction()

function(strata_test_library name)
  _strata_test_sources(sources ${name} ${ARGN})
  add_library(${name} STATIC ${sources})
  _strata_test_target(${name})
endfunction()

function(_strata_test_sources out name)
  if(NOT STRATA_TEST_OBJECTS_FROM)
    # Written when the build is generated, after cmake/Unity.cmake has batched the sources.
    file(GENERATE OUTPUT ${PROJECT_BINARY_DIR}/test-objects/${name}.txt
         CONTENT "$<JOIN:$<TARGET_OBJECTS:${name}>,\n>\n")
    set(${out} ${ARGN} PARENT_SCOPE)
    return()
  endif()
  set(list ${STRATA_TEST_OBJECTS_FROM}/test-objects/${name}.txt)
  if(NOT EXISTS ${list})
    message(FATAL_ERROR "${list} is missing: ${STRATA_TEST_OBJECTS_FROM} was configured without "
                        "${name} (STRATA_BUILD_TESTS=OFF, or a dependency it needs not found)")
  endif()
  file(STRINGS ${list} objects)
  # The other build, configured again, may batch its sources anew: then this one configures again.
  set_property(DIRECTORY ${PROJECT_SOURCE_DIR} APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${list})
  # They are made by the other build, maybe after this one is configured.
  set_source_files_properties(${objects} PROPERTIES EXTERNAL_OBJECT TRUE GENERATED TRUE)
  set(${out} ${objects} PARENT_SCOPE)
endfunction()

function(_strata_test_target name)
  set_property(GLOBAL APPEND PROPERTY STRATA_TEST_CODE_TARGETS ${name})
  if(STRATA_TEST_OBJECTS_FROM)
    set_target_properties(${name} PROPERTIES EXCLUDE_FROM_ALL ON LINKER_LANGUAGE CXX)
  endif()
endfunction()

# strata_test_code_target(): `strata_test_code` builds every target made above. Called once,
# after the last of them.
function(strata_test_code_target)
  get_property(targets GLOBAL PROPERTY STRATA_TEST_CODE_TARGETS)
  add_custom_target(strata_test_code DEPENDS ${targets})
endfunction()
