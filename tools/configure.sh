#!/usr/bin/env bash
# Configures build/ the one way the README's commands use it (tools/setup.sh --build, then
# tools/test.sh): the same settings each time, so the second command reuses every object of the
# first. ccache and warnings-as-errors come from CMakeLists.txt (cmake/Ccache.cmake), not from here.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cmake -S "$root" -B "$root/build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
