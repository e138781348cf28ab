#!/usr/bin/env bash
# The whole test suite on a fresh machine: install dependencies, build, run every test.
# Usage: tools/test.sh   (build dir: build/, configured as tools/setup.sh --build does)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/tools/setup.sh"
"$root/tools/configure.sh"
cmake --build "$root/build" -j "$(nproc)"
ctest --test-dir "$root/build" --output-on-failure -j "$(nproc)"
