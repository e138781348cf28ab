#!/usr/bin/env bash
# The whole test suite on a fresh machine: install dependencies, build, run every test.
# Usage: tools/test.sh            (build dir: build/)
#   STRATA_WERROR=1 tools/test.sh   treat warnings as errors (CI does)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/tools/setup.sh"
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  export CCACHE_BASEDIR="$root"  # relative paths: clones in other folders share the cache
fi
cmake -S "$root" -B "$root/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DSTRATA_WARNINGS_AS_ERRORS="${STRATA_WERROR:-0}" "${launcher[@]}"
cmake --build "$root/build" -j "$(nproc)"
ctest --test-dir "$root/build" --output-on-failure -j "$(nproc)"
