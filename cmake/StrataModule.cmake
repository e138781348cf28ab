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
  strata_unity(${target})
endfunction()

# strata_add_gtest(<name> <sources...> LINKS <targets...>): one test binary, discovered by CTest.
function(strata_add_gtest name)
  cmake_parse_arguments(ARG "" "" "LINKS" ${ARGN})
  add_executable(${name} ${ARG_UNPARSED_ARGUMENTS})
  target_link_libraries(${name} PRIVATE ${ARG_LINKS} GTest::gtest GTest::gtest_main)
  strata_use_build_paths(${name})  # STRATA_DATA_DIR, STRATA_SOURCE_DIR, STRATA_BINARY
  target_include_directories(${name} PRIVATE ${PROJECT_SOURCE_DIR}/tests/support)  # TempPath.hpp
  strata_set_warnings(${name})
  strata_unity(${name})
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60 PROPERTIES TIMEOUT 600)
endfunction()
