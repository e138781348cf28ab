#!/usr/bin/env bash
# The whole test suite on a fresh machine: install dependencies, build, run every test.
# Usage: tools/test.sh   (build dir: build/, configured as tools/setup.sh --build does)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)

# The least number of tests the suite may hold (`ctest -N`): 418 on 2026-12-05 with Google
# Benchmark, Open MPI and pybind11 found, held a little below. Those three are optional lookups
# (QUIET or not REQUIRED), so a machine without one of them drops whole groups of tests and
# CTest would pass on what is left; below the floor, or with a group below missing, the run
# fails before any test runs. Raise it when tests are added.
min_tests=410
# Each group an optional dependency brings: a test that names it, and what is missing without it.
groups=("BenchIntegrationCi|the benchmarks' tests (bench/: Google Benchmark, libbenchmark-dev)"
        "Mpi.Ranks2|the MPI tests (tests/scale/: Open MPI, libopenmpi-dev)"
        "python_pytest|the Python module's tests (tests/python/: pybind11-dev, python3-dev)")

"$root/tools/setup.sh"
"$root/tools/configure.sh"
cmake --build "$root/build" -j "$(nproc)"

listed=$(ctest --test-dir "$root/build" -N)
count=$(sed -n 's/^Total Tests: //p' <<<"$listed")
short=0
for group in "${groups[@]}"; do
  if ! grep -qE "Test +#[0-9]+: ${group%%|*}\$" <<<"$listed"; then
    echo "test.sh: missing ${group#*|}" >&2
    short=1
  fi
done
if ((${count:-0} < min_tests)); then
  echo "test.sh: ${count:-0} tests listed, fewer than min_tests=$min_tests (tools/test.sh)" >&2
  short=1
fi
((short == 0)) || exit 1
# The fixtures the test processes share, each made once in this run by the first test that wants
# it (tests/support/SharedFixture.hpp), in a folder of this run's own.
STRATA_TEST_FIXTURES=$(mktemp -d "${TMPDIR:-/tmp}/strata_fixtures_XXXXXX")
export STRATA_TEST_FIXTURES
trap 'rm -rf "$STRATA_TEST_FIXTURES"' EXIT
# CTest counts a skipped test as passed: with STRATA_REQUIRE_DATA=1 (.ci/run) a skip fails the
# run (the real-data tests also fail by themselves then, tests/support/RealData.hpp).
log="$root/build/ctest-last.log"
status=0
ctest --test-dir "$root/build" --output-on-failure -j "$(nproc)" 2>&1 | tee "$log" || status=$?
if [[ ${STRATA_REQUIRE_DATA:-} == 1 ]] && grep -q '(Skipped)' "$log"; then
  echo "test.sh: STRATA_REQUIRE_DATA=1 and these tests skipped:" >&2
  grep '(Skipped)' "$log" >&2
  status=1
fi
exit $status
