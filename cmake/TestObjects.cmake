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
# The same for the third-party templates strata compiles once (src/core/CMakeLists.txt,
# `strata_templates`: OpenVDB's grid types and their dilation, Eigen's symmetric eigen-solver),
# with -DSTRATA_TEMPLATES_FROM=<another build of this tree>: CI's ASan build takes them from
# build/ (.ci/run compiles them there first). OpenVDB's trees compiled whole are the most
# expensive files of every build (100 s of g++, about 200 s under ASan + UBSan, 2026-12-07), and
# none of it is strata's own code: taken from build/ they run uninstrumented, like the rest of
# libopenvdb and Debian's g++-built Ceres, whose solvers call the same Eigen code. Not under TSan: the TBB hand-overs inlined in them (Tree::clear's
# task group) would be invisible to it and reported as races (docs/reliability.md, "What the
# builds cost alone, four levers left and one taken").
#
# In such a build the test-side targets are left out of `all` (their objects may not exist
# yet when it starts: .ci/run builds the sanitizer libraries while build/ compiles); the target
# `strata_test_code` builds them, in any build.
set(STRATA_TEST_OBJECTS_FROM "" CACHE PATH
    "Link the test programs from the objects of this other build of the tree (CI's ASan build)")

set(STRATA_TEMPLATES_FROM "" CACHE PATH
    "Link the compiled templates from this other build's objects (CI's ASan build)")

# The other build must be a configured build of this very tree.
foreach(_variable STRATA_TEST_OBJECTS_FROM STRATA_TEMPLATES_FROM)
  set(_dir ${${_variable}})
  if(NOT _dir)
    continue()
  endif()
  if(NOT EXISTS ${_dir}/CMakeCache.txt)
    message(FATAL_ERROR "${_variable}=${_dir} is not a configured "
                        "build directory (configure it first: tools/configure.sh makes build/)")
  endif()
  load_cache(${_dir} READ_WITH_PREFIX _from_ CMAKE_HOME_DIRECTORY)
  file(REAL_PATH "${_from_CMAKE_HOME_DIRECTORY}" _from_source)
  file(REAL_PATH "${PROJECT_SOURCE_DIR}" _our_source)
  if(NOT _from_source STREQUAL _our_source)
    message(FATAL_ERROR "${_variable}=${_dir} is a build of "
                        "${_from_CMAKE_HOME_DIRECTORY}, not of this tree (${PROJECT_SOURCE_DIR})")
  endif()
endforeach()

# strata_objects_from(<out> <name> <from> <sources...>): <sources> when <from> is empty (and the
# list of <name>'s objects written for other builds), else <from>'s objects of <name>.
function(strata_objects_from out name from)
  if(NOT from)
    # Written when the build is generated, after cmake/Unity.cmake has batched the sources.
    file(GENERATE OUTPUT ${PROJECT_BINARY_DIR}/test-objects/${name}.txt
         CONTENT "$<JOIN:$<TARGET_OBJECTS:${name}>,\n>\n")
    set(${out} ${ARGN} PARENT_SCOPE)
    return()
  endif()
  set(list ${from}/test-objects/${name}.txt)
  if(NOT EXISTS ${list})
    message(FATAL_ERROR "${list} is missing: ${from} was configured without ${name} (for "
                        "test code: STRATA_BUILD_TESTS=OFF, or a dependency it needs not found)")
  endif()
  file(STRINGS ${list} objects)
  # The other build, configured again, may batch its sources anew: then this one configures again.
  set_property(DIRECTORY ${PROJECT_SOURCE_DIR} APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${list})
  # They are made by the other build, maybe after this one is configured.
  set_source_files_properties(${objects} PROPERTIES EXTERNAL_OBJECT TRUE GENERATED TRUE)
  set(${out} ${objects} PARENT_SCOPE)
endfunction()

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
  strata_objects_from(sources ${name} "${STRATA_TEST_OBJECTS_FROM}" ${ARGN})
  set(${out} ${sources} PARENT_SCOPE)
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
