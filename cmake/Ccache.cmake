# Every build directory compiles through ccache when it is installed, with the same settings
# whoever configures it (tools/setup.sh, tools/test.sh, the sanitizer scripts, an IDE), so the
# README's two commands share their objects and clones in other folders share the cache.
# CCACHE_BASEDIR=<source root> makes ccache hash the paths under it relative to the build
# directory. -DSTRATA_CCACHE=OFF, or a CMAKE_CXX_COMPILER_LAUNCHER of your own, opts out.
option(STRATA_CCACHE "Compile through ccache when it is installed" ON)
if(STRATA_CCACHE AND NOT CMAKE_CXX_COMPILER_LAUNCHER)
  find_program(STRATA_CCACHE_PROGRAM ccache)
  if(STRATA_CCACHE_PROGRAM)
    # pch_defines,time_macros: what ccache needs to cache files that use a precompiled header
    # (cmake/Pch.cmake; ccache's manual, "Precompiled headers").
    set(CMAKE_CXX_COMPILER_LAUNCHER env CCACHE_BASEDIR=${PROJECT_SOURCE_DIR}
                                    CCACHE_SLOPPINESS=pch_defines,time_macros
                                    ${STRATA_CCACHE_PROGRAM})
  endif()
endif()
