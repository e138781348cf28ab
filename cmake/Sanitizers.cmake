# Sanitizer builds (docs/reliability.md, "Sanitizers"), each in a build directory of its own, with
# clang, instrumenting everything the build compiles so a bug in a library is caught where it is:
#   STRATA_BUILD_FUZZ=ON    libFuzzer coverage + ASan + UBSan: tools/fuzz.sh, tools/sanitize.sh asan
#   STRATA_SANITIZE=thread  ThreadSanitizer: tools/sanitize.sh tsan
set(STRATA_SANITIZE "" CACHE STRING "Build everything with a sanitizer: empty or 'thread'")
set_property(CACHE STRATA_SANITIZE PROPERTY STRINGS "" thread)

if(STRATA_BUILD_FUZZ OR STRATA_SANITIZE)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "STRATA_BUILD_FUZZ and STRATA_SANITIZE need clang, but the C++ compiler "
                        "is ${CMAKE_CXX_COMPILER_ID}: configure a fresh build directory with "
                        "-DCMAKE_CXX_COMPILER=clang++ (tools/fuzz.sh and tools/sanitize.sh do)")
  endif()
  # After the build type's -O2 -g, so these win: line tables only, all a sanitizer report
  # needs. With debug information ccache hashes the build directory; mapped to a path relative
  # to the source root, it is the same in every clone (cmake/Ccache.cmake).
  add_compile_options(-gline-tables-only -fdebug-prefix-map=${PROJECT_SOURCE_DIR}=.)
endif()

if(STRATA_BUILD_FUZZ AND STRATA_SANITIZE)
  message(FATAL_ERROR "STRATA_BUILD_FUZZ builds with ASan + UBSan already; "
                      "STRATA_SANITIZE=${STRATA_SANITIZE} needs a build directory of its own")
elseif(STRATA_BUILD_FUZZ)
  # ASan + UBSan on everything; libFuzzer's coverage only on the libraries the fuzz targets run
  # (tests/fuzz/CMakeLists.txt), and only the fuzz targets link libFuzzer's main
  # (-fsanitize=fuzzer), so the same objects make the test binaries of the ASan + UBSan run
  # too. The ignorelist gives the reason for each entry. Its path is
  # relative to the build directory, where Ninja runs the compiler: ccache hashes the flag as
  # written, and an absolute path would differ between clones. ccache does not read the file,
  # so its checksum goes into a definition: a changed ignorelist recompiles everything.
  set(ignorelist ${PROJECT_SOURCE_DIR}/tests/fuzz/SanitizerIgnorelist.txt)
  file(RELATIVE_PATH ignorelist_relative ${PROJECT_BINARY_DIR} ${ignorelist})
  file(MD5 ${ignorelist} ignorelist_md5)
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${ignorelist})
  # Less UBSan's object-size check, which ASan's checks of every access cover: it kept clang
  # from inlining Eigen, OpenVDB and the standard library (a 3x3 matrix times a vector left 72
  # out-of-line Eigen functions with it, 22 without) and made the ASan tests ~30 % slower at
  # -O2 (docs/reliability.md, "Sanitizers").
  add_compile_options(-fsanitize=address,undefined -fno-sanitize=object-size
                      -fno-sanitize-recover=undefined -fno-omit-frame-pointer
                      -fsanitize-ignorelist=${ignorelist_relative}
                      -Wno-unknown-warning-option)  # cmake/Warnings.cmake has gcc's -Wshadow=local
  add_compile_definitions(STRATA_SANITIZER_IGNORELIST_MD5=${ignorelist_md5})
  add_link_options(-fsanitize=address,undefined)
elseif(STRATA_SANITIZE STREQUAL "thread")
  # TBB's scheduler must be instrumented too, or every hand-over of work between its threads is
  # reported as a race: tools/sanitize.sh builds libtbb from Debian's source package with TSan
  # and puts it first on LD_LIBRARY_PATH for the tests (docs/reliability.md, "Sanitizers").
  # -O1: the TSan tests are short, and it compiles the OpenVDB-heavy files faster.
  add_compile_options(-O1 -fsanitize=thread -fno-omit-frame-pointer
                      -Wno-unknown-warning-option)  # cmake/Warnings.cmake has gcc's -Wshadow=local
  add_link_options(-fsanitize=thread)
elseif(STRATA_SANITIZE)
  message(FATAL_ERROR "STRATA_SANITIZE='${STRATA_SANITIZE}': the only value is 'thread' "
                      "(ASan + UBSan come with STRATA_BUILD_FUZZ=ON, tools/sanitize.sh asan)")
endif()
