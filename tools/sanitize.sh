#!/usr/bin/env bash
# Runs tests under clang's sanitizers; fails on a failing test or on any sanitizer report, also
# one from a `strata` child process that a test expected to fail. docs/reliability.md, "Sanitizers".
# Usage: tools/sanitize.sh asan [CTEST_ARGS...]
#          every test with AddressSanitizer + UndefinedBehaviorSanitizer, in build-fuzz/: the
#          objects of tools/fuzz.sh (same compiler and flags) with tests and tools added, so
#          one compile of the libraries serves both.
#        tools/sanitize.sh tsan [CTEST_ARGS...]
#          the parallel paths with ThreadSanitizer, in build-tsan/: only the test programs in
#          $tsan_targets are built and the tests matching $tsan_tests run. libtbb is built
#          with TSan from Debian's source package of the installed libtbb-dev, which
#          `tools/setup.sh --sanitizers` fetches (no download here), else every hand-over
#          between TBB threads is a report.
#   STRATA_BUILD_JOBS=2  build parallelism   STRATA_TEST_JOBS=2  ctest -j
#   STRATA_SANITIZE_TARGETS="test_store"  build only these programs; pass the matching -R Store
#   STRATA_SANITIZE_MIN_TESTS=N  fail when fewer than N tests are selected (.ci/run sets it;
#          default: $tsan_min_tests for tsan without arguments, else 1). With no test selected
#          ctest itself fails (--no-tests=error).
#   STRATA_ASAN_TEST_OBJECTS_FROM=DIR  asan: link the test programs from the objects of DIR, a
#          build of this tree, instead of compiling the tests' own code with the sanitizers; the
#          libraries, the program and the fuzz targets are instrumented as always (.ci/run sets
#          it to build/: cmake/TestObjects.cmake)
#   STRATA_ASAN_TEMPLATES_FROM=DIR  asan: take the compiled third-party templates (OpenVDB's grid
#          types and dilation, Eigen's eigen-solver) from DIR's objects (its `strata_templates`),
#          uninstrumented, instead of compiling them again with the sanitizers (.ci/run sets
#          it to build/ and compiles them there first: cmake/TestObjects.cmake). Not for tsan:
#          TBB's hand-overs inlined in those objects would be invisible to it, and it reports
#          them as races.
#   STRATA_SANITIZE_BUILD_ONLY=1  build (and for tsan, libtbb) and stop: .ci/run builds both
#          in the background while the normal build's tests run, then runs the tests here.
# Sanitizer reports land in build-*/sanitizer-reports/ (one file per process, printed on failure).
# Tests read STRATA_SANITIZER (address or thread, set here) to shrink what is too slow there.
set -euo pipefail
shopt -s inherit_errexit  # BuildTsanTbb runs in $(...): stop at its first failure too
root=$(cd "$(dirname "$0")/.." && pwd)
mode=${1:-}
if [[ $mode != asan && $mode != tsan ]]; then
  echo "usage: tools/sanitize.sh asan|tsan [CTEST_ARGS...]" >&2
  exit 2
fi
shift
jobs=${STRATA_BUILD_JOBS:-$(nproc)}

# The parallel paths: the integrator's TBB loops (ResultDoesNotDependOnThreadCount runs 1 and 4
# threads), the store's parallel tile writes and reads with a reader thread against a writer,
# the simulator's Embree sweeps, the change detector's parallel tile loads, the vehicle stage's
# Embree ray checks, registration's parallel matching and the walls' stages after DBSCAN
# (FindWalls: K-means, the part tests and the fits in parallel; WallAssembler's slotted wall:
# one assembler's state handed to another; the matching surface read from a map's tiles by
# threads, MapSurface). Reader processes against a
# writer process (StoreFaults) are left to ASan: TSan sees threads, not processes, and the store's
# threads are the in-process reader test's. Tests of other things (most store tests take
# minutes under TSan) run under ASan only.
tsan_targets=(test_integration test_store test_sim test_change test_vehicles test_registration
              test_walls)
tsan_tests='^(Integrator|Limits|Simulator|ChangeDetection|RayCheck|ClearVehicles|FindWalls)\.'
tsan_tests+='|^OctomapAgreement\.SeveralSynthetic|^RegistrationIcp\.Recovers'
tsan_tests+='|^Store\.(SessionsEqualInMemory|OneWriterAtATime|ReadersSeeWholeCommits)'
tsan_tests+='|^WallAssembler\.(AWallCutByASlot|WhatOneReleases)'
tsan_tests+='|^MapSurface\.|^SessionCloud\.'
# What the TSan selection held (44 on 2026-12-02, the 3 FindWalls tests and 2 WallAssembler
# tests since 2026-12-04, the matching surface read from a map's tiles by threads and the
# session cloud since 2026-12-05;
# docs/reliability.md, "Sanitizers"): a filter or a build change that drops tests fails the run
# instead of passing on fewer. Raise it when tests are added.
tsan_min_tests=52

if ! command -v clang++ >/dev/null; then
  echo "sanitize.sh: clang++ not found (tools/setup.sh installs it)" >&2
  exit 1
fi
# libtbb's own build goes through ccache as strata's does (cmake/Ccache.cmake), with its build
# folder mapped in the debug information so that clones in other folders share the cache.
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER="env;CCACHE_BASEDIR=$root;ccache"
            -DCMAKE_CXX_FLAGS="-fdebug-prefix-map=$root=.")
fi
start=$(date +%s)

# Builds libtbb with TSan from Debian's source package of the installed version (tools/setup.sh
# fetches it into /var/cache/strata/) into $1/tbb; prints the folder holding libtbb.so.12.
BuildTsanTbb() {
  local dir=$1 version source lib
  version=$(dpkg-query -W -f='${Version}' libtbb-dev)
  source=${STRATA_TBB_SOURCE_DIR:-/var/cache/strata/onetbb-$version}
  lib=$(find "$dir/tbb" -name libtbb.so.12 2>/dev/null | head -1 || true)
  if [[ -n $lib && -f $dir/onetbb/version && $(cat "$dir/onetbb/version") == "$version" ]]; then
    dirname "$lib"
    return
  fi
  if ! compgen -G "$source/onetbb_*.dsc" >/dev/null; then
    echo "sanitize.sh: no source of libtbb $version in $source: run tools/setup.sh --sanitizers" >&2
    exit 1
  fi
  rm -rf "$dir/onetbb" "$dir/tbb"
  mkdir -p "$dir/onetbb"
  # --no-check: apt-get verified the files against the signed Sources index when setup.sh fetched
  # them; the .dsc's own signature needs the maintainers' keys (debian-keyring), not installed.
  dpkg-source --no-check -x "$source"/onetbb_*.dsc "$dir/onetbb/tree" >/dev/null
  cmake -S "$dir/onetbb/tree" -B "$dir/tbb" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_COMPILER=clang++ -DTBB_SANITIZE=thread -DTBB_TEST=OFF \
    -DTBBMALLOC_BUILD=OFF -DTBB_STRICT=OFF "${launcher[@]}" >/dev/null
  cmake --build "$dir/tbb" -j "$jobs" >&2
  echo "$version" >"$dir/onetbb/version"
  dirname "$(find "$dir/tbb" -name libtbb.so.12 | head -1)"
}

# No Python module: an instrumented extension cannot load into Debian's uninstrumented
# interpreter (the ASan runtime must come first); its C++ is the libraries tested here.
common=(-G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++
        -DSTRATA_BUILD_TESTS=ON -DSTRATA_BUILD_TOOLS=ON -DSTRATA_BUILD_BENCH=OFF
        -DSTRATA_BUILD_PYTHON=OFF)

if [[ $mode == asan ]]; then
  build="$root/build-fuzz"
  # STRATA_ASAN_TEST_OBJECTS_FROM=DIR (.ci/run: build/): the test code comes from DIR's objects
  # (cmake/TestObjects.cmake); unset, it is compiled here with the sanitizers.
  objects_from=${STRATA_ASAN_TEST_OBJECTS_FROM:-}
  [[ -n $objects_from ]] && objects_from=$(cd "$objects_from" && pwd)
  # STRATA_ASAN_TEMPLATES_FROM=DIR: DIR's compiled templates are brought up to date first, unless
  # this is a build-only run (.ci/run's background build, which starts after it compiled them in
  # build/ and while build/ compiles the rest: a second ninja in DIR then would race the first).
  templates_from=${STRATA_ASAN_TEMPLATES_FROM:-}
  if [[ -n $templates_from ]]; then
    templates_from=$(cd "$templates_from" && pwd)
    if [[ ${STRATA_SANITIZE_BUILD_ONLY:-} != 1 ]]; then
      cmake --build "$templates_from" -j "$jobs" --target strata_templates
    fi
  fi
  cmake -S "$root" -B "$build" "${common[@]}" -DSTRATA_BUILD_FUZZ=ON \
    -DSTRATA_TEST_OBJECTS_FROM="$objects_from" -DSTRATA_TEMPLATES_FROM="$templates_from" \
    >/dev/null
  # With DIR the test code is left out of `all`: DIR's objects are brought up to date with the
  # tree first, and `strata_test_code` links the test programs here. A build-only run (.ci/run's
  # background build, which starts while DIR compiles) builds the rest and stops.
  reuse=0
  [[ -n $objects_from && ${STRATA_SANITIZE_BUILD_ONLY:-} != 1 ]] && reuse=1
  if ((reuse)); then
    cmake --build "$objects_from" -j "$jobs" --target ${STRATA_SANITIZE_TARGETS:-strata_test_code}
  fi
  cmake --build "$build" -j "$jobs" ${STRATA_SANITIZE_TARGETS:+--target $STRATA_SANITIZE_TARGETS}
  if ((reuse)) && [[ -z ${STRATA_SANITIZE_TARGETS:-} ]]; then
    cmake --build "$build" -j "$jobs" --target strata_test_code
  fi
  filter=()
  export STRATA_SANITIZER=address
else
  build="$root/build-tsan"
  mkdir -p "$build"
  tbb_lib=$(BuildTsanTbb "$build")
  export LD_LIBRARY_PATH="$tbb_lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
  cmake -S "$root" -B "$build" "${common[@]}" -DSTRATA_SANITIZE=thread >/dev/null
  cmake --build "$build" -j "$jobs" --target ${STRATA_SANITIZE_TARGETS:-${tsan_targets[*]}}
  # The libraries every test program links resolve libtbb to the TSan build's (checked on one of
  # them: STRATA_SANITIZE_TARGETS may leave any program out). ldd's whole output first: `ldd |
  # grep -q` under pipefail fails at random when grep exits on its match before ldd has written
  # its last line (SIGPIPE), as one CI run did.
  loads=$(ldd "$build/src/core/libstrata_core.so")
  if [[ $loads != *"$tbb_lib/libtbb.so.12 "* ]]; then
    echo "sanitize.sh: strata's libraries do not load the TSan libtbb in $tbb_lib:" >&2
    echo "$loads" >&2
    exit 1
  fi
  filter=(-R "$tsan_tests")
  export STRATA_SANITIZER=thread
fi
echo "sanitize.sh: $mode build took $(($(date +%s) - start)) s"
[[ ${STRATA_SANITIZE_BUILD_ONLY:-} == 1 ]] && exit 0

reports="$build/sanitizer-reports"
rm -rf "$reports"
mkdir -p "$reports"
# Leak checking is off: OpenVDB and TBB keep process-lifetime allocations that are not bugs.
export ASAN_OPTIONS="detect_leaks=0:log_path=$reports/asan"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:log_path=$reports/ubsan"
# Suppressions only for races inside OpenVDB's and Embree's uninstrumented TBB loops; the file
# gives the reason for each.
export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:log_path=$reports/tsan"
TSAN_OPTIONS+=":suppressions=$root/tools/tsan-suppressions.txt"
# Programs left unbuilt on purpose show up in ctest as <program>_NOT_BUILT.
[[ -n ${STRATA_SANITIZE_TARGETS:-} ]] && filter+=(-E _NOT_BUILT)
min_tests=1
[[ $mode == tsan && $# -eq 0 && -z ${STRATA_SANITIZE_TARGETS:-} ]] && min_tests=$tsan_min_tests
min_tests=${STRATA_SANITIZE_MIN_TESTS:-$min_tests}
selected=$(ctest --test-dir "$build" -N "${filter[@]}" "$@" | grep -c '^ *Test *#' || true)
echo "sanitize.sh: $selected tests selected (at least $min_tests expected)"
if ((selected < min_tests)); then
  echo "sanitize.sh: only $selected tests selected, expected at least $min_tests" >&2
  exit 1
fi
# The fixtures the test processes share, each made once in this run by the first test that wants
# it (tests/support/SharedFixture.hpp), in a folder of this run's own.
STRATA_TEST_FIXTURES=$(mktemp -d "${TMPDIR:-/tmp}/strata_fixtures_XXXXXX")
export STRATA_TEST_FIXTURES
trap 'rm -rf "$STRATA_TEST_FIXTURES"' EXIT
test_start=$(date +%s)
status=0
ctest --test-dir "$build" --output-on-failure --no-tests=error \
  -j "${STRATA_TEST_JOBS:-$(nproc)}" "${filter[@]}" "$@" || status=$?
end=$(date +%s)
echo "sanitize.sh: $mode tests took $((end - test_start)) s, $((end - start)) s in all"
if compgen -G "$reports/*" >/dev/null; then
  echo "sanitize.sh: sanitizer reports from $(ls "$reports" | wc -l) processes:" >&2
  for f in "$reports"/*; do echo "== $f" >&2; head -60 "$f" >&2; done
  status=1
fi
exit $status
