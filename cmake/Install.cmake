# What `cmake --install build [--prefix P]` puts where (README, "Install"), and the Debian package
# `cpack -G DEB` makes of the same files (prefix /usr):
#   bin/strata                                   the program
#   lib/strata/                                  the stage libraries the program and module load
#   lib/python3.11/dist-packages/strata/         the Python module (python/CMakeLists.txt)
#   share/man/man1/strata.1, strata-<command>.1  one page per subcommand, from its --help
#   share/bash-completion/completions/strata     subcommands and options, from the same --help
#   share/doc/strata/                            README.md, docs/, datasets/ (the scenes)
# Nothing installed loads anything from the build directory (tests/tools/test_install.py checks).
include(GNUInstallDirs)
# Runs HelpPages.py and the install test: Debian's interpreter, as for the module
# (python/CMakeLists.txt), which has pytest.
if(NOT DEFINED Python3_EXECUTABLE AND EXISTS /usr/bin/python3)
  set(Python3_EXECUTABLE /usr/bin/python3 CACHE FILEPATH "Interpreter the module is built for")
endif()
find_package(Python3 COMPONENTS Interpreter QUIET)

if(TARGET strata)
  install(TARGETS strata RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

  # Man pages and the completion script, generated from the program's own --help whenever the
  # program is relinked, so they list exactly the options it takes. Left out of the sanitizer
  # builds, which are never installed: there each of the program's ~20 runs is slow.
  if(Python3_Interpreter_FOUND AND NOT STRATA_BUILD_FUZZ AND NOT STRATA_SANITIZE)
    set(help_pages ${PROJECT_BINARY_DIR}/help-pages)
    set(help_script ${PROJECT_SOURCE_DIR}/tools/strata/HelpPages.py)
    add_custom_command(OUTPUT ${help_pages}/stamp
      COMMAND ${Python3_EXECUTABLE} ${help_script} $<TARGET_FILE:strata> ${help_pages}
      COMMAND ${CMAKE_COMMAND} -E touch ${help_pages}/stamp
      DEPENDS strata ${help_script}
      COMMENT "Man pages and bash completion from strata --help" VERBATIM)
    add_custom_target(strata_help_pages ALL DEPENDS ${help_pages}/stamp)
    install(DIRECTORY ${help_pages}/man1 DESTINATION ${CMAKE_INSTALL_MANDIR})
    install(FILES ${help_pages}/completion/strata
            DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions)
  else()
    message(STATUS "strata man pages and bash completion: not generated (needs python3; "
                   "never in sanitizer builds)")
  endif()
endif()

# The stage libraries are shared (Debian's FindOpenVDB.cmake turns BUILD_SHARED_LIBS on for the
# whole project). They are private to strata, so they go to lib/strata rather than lib/, and the
# program and the Python module find them there through a RUNPATH relative to themselves: a
# prefix can move. Each library finds its neighbours through $ORIGIN.
get_property(modules GLOBAL PROPERTY STRATA_MODULE_TARGETS)
set(shared_modules)
foreach(module IN LISTS modules)
  get_target_property(type ${module} TYPE)
  if(type STREQUAL "SHARED_LIBRARY")
    list(APPEND shared_modules ${module})
  endif()
endforeach()
if(shared_modules)
  set(strata_libdir ${CMAKE_INSTALL_LIBDIR}/strata)
  set_target_properties(${shared_modules} PROPERTIES INSTALL_RPATH "$ORIGIN")
  install(TARGETS ${shared_modules} LIBRARY DESTINATION ${strata_libdir})
  if(TARGET strata)
    set_target_properties(strata PROPERTIES INSTALL_RPATH "$ORIGIN/../${strata_libdir}")
  endif()
  if(TARGET _strata)
    if(IS_ABSOLUTE ${STRATA_PYTHON_INSTALL_DIR})  # then only the configured prefix can do
      set(runpath ${CMAKE_INSTALL_PREFIX}/${strata_libdir})
    else()
      file(RELATIVE_PATH relative /${STRATA_PYTHON_INSTALL_DIR}/strata /${strata_libdir})
      set(runpath "$ORIGIN/${relative}")
    endif()
    set_target_properties(_strata PROPERTIES INSTALL_RPATH ${runpath})
  endif()
endif()

# The docs keep their folder layout, so the README's links (docs/python.md) and the docs' links
# (../datasets/README.md) still work where they are installed.
install(FILES README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY docs datasets DESTINATION ${CMAKE_INSTALL_DOCDIR})

# The Debian package: `cpack -G DEB` in the build directory, after the build, writes
# strata_<version>_amd64.deb. Its dependencies are the packages whose shared libraries the
# program and the module load (dpkg-shlibdeps reads them from the installed files), the Python
# the module is built for, numpy, and three.js, which `strata view` serves from libjs-three.
set(STRATA_DEB_MAINTAINER "strata maintainers" CACHE STRING
    "Maintainer field of the Debian package (name <address>)")
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME strata)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "GPU-free voxel database for LiDAR maps")
string(CONCAT CPACK_PACKAGE_DESCRIPTION
  "strata turns posed LiDAR scans into sparse OpenVDB grids with per-voxel semantics, kept in "
  "an on-disk transactional store with sessions; it finds walls, parked vehicles and changes, "
  "registers scans, and exports to VDB, OctoMap, PLY and PNG. This package holds the strata "
  "program, its Python module, man pages, bash completion and documentation.")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_MAINTAINER ${STRATA_DEB_MAINTAINER})
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(strata_deb_depends libjs-three)
if(TARGET _strata)
  math(EXPR next_minor "${Python3_VERSION_MINOR} + 1")
  set(python python${Python3_VERSION_MAJOR})
  list(APPEND strata_deb_depends
       "${python} (>= ${Python3_VERSION_MAJOR}.${Python3_VERSION_MINOR})"
       "${python} (<< ${Python3_VERSION_MAJOR}.${next_minor})" ${python}-numpy)
endif()
list(JOIN strata_deb_depends ", " CPACK_DEBIAN_PACKAGE_DEPENDS)
include(CPack)
