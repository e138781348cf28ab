#!/usr/bin/env bash
# Installs strata's build dependencies from Debian 12 packages (idempotent; run as root or with sudo).
# Usage: tools/setup.sh            install only
#        tools/setup.sh --build    install, then configure and build into build/
set -euo pipefail

packages=(
  build-essential cmake ninja-build ccache pkg-config
  libopenvdb-dev libboost-iostreams-dev libblosc-dev  # libopenvdb-dev does not pull boost-iostreams
  libopenvdb-tools                                    # vdb_print, to check exports
  liboctomap-dev libeigen3-dev libceres-dev libembree-dev libtbb-dev
  libsqlite3-dev sqlite3 libcli11-dev nlohmann-json3-dev liblzf-dev libxxhash-dev libpng-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  bzip2 libbz2-dev
  clang libclang-rt-14-dev  # tools/fuzz.sh: libFuzzer and the sanitizer runtimes (clang 14)
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if ((${#missing[@]})); then
  sudo_cmd=()
  [[ $(id -u) -eq 0 ]] || sudo_cmd=(sudo)
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -qq
  "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

if [[ "${1:-}" == "--build" ]]; then
  root=$(cd "$(dirname "$0")/.." && pwd)
  cmake -S "$root" -B "$root/build" -G Ninja -DCMAKE_BUILD_TYPE=Release
  cmake --build "$root/build"
fi
