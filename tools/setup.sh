#!/usr/bin/env bash
# Installs strata's build dependencies from Debian 12 packages (idempotent; run as root or with sudo).
# Usage: tools/setup.sh                install only
#        tools/setup.sh --build        install, then configure and build into build/
#        tools/setup.sh --sanitizers   install, and fetch the source of libtbb for
#                                      tools/sanitize.sh tsan (.ci/run does)
set -euo pipefail
build=0
sanitizers=0
for arg in "$@"; do
  case $arg in
    --build) build=1 ;;
    --sanitizers) sanitizers=1 ;;
    *) echo "usage: tools/setup.sh [--build] [--sanitizers]" >&2; exit 2 ;;
  esac
done

packages=(
  build-essential cmake ninja-build ccache pkg-config
  libopenvdb-dev libboost-iostreams-dev libblosc-dev  # libopenvdb-dev does not pull boost-iostreams
  libopenvdb-tools                                    # vdb_print, to check exports
  liboctomap-dev libeigen3-dev libceres-dev libembree-dev libtbb-dev
  libsqlite3-dev sqlite3 libcli11-dev nlohmann-json3-dev liblzf-dev libxxhash-dev libpng-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  bzip2 libbz2-dev
  clang libclang-rt-14-dev  # tools/fuzz.sh: libFuzzer and the sanitizer runtimes (clang 14)
  libcpp-httplib-dev libjs-three                     # strata view: its server, three.js
  chromium python3-pytest python3-websocket          # strata view's browser tests
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

# The source package of the installed libtbb, for tools/sanitize.sh tsan: ThreadSanitizer needs
# a libtbb built with it (docs/reliability.md, "Sanitizers"). Fetched here, with the packages, so
# that builds never download; apt-get checks the files against Debian's signed index. A private
# source list and state keep the machine's apt configuration untouched.
tbb_version=$(dpkg-query -W -f='${Version}' libtbb-dev)
tbb_source=${STRATA_TBB_SOURCE_DIR:-/var/cache/strata/onetbb-$tbb_version}
if ((sanitizers)) && ! compgen -G "$tbb_source/onetbb_*.dsc" >/dev/null; then
  sudo_cmd=()
  [[ $(id -u) -eq 0 ]] || sudo_cmd=(sudo)
  apt_dir=$(mktemp -d)
  trap 'rm -rf "$apt_dir"' EXIT
  mkdir -p "$apt_dir/lists/partial" "$apt_dir/cache/archives/partial"
  {
    printf 'deb-src http://deb.debian.org/debian %s main\n' bookworm bookworm-updates
    echo 'deb-src http://deb.debian.org/debian-security bookworm-security main'
  } >"$apt_dir/sources.list"
  apt_opts=(-qq -o "Dir::Etc::SourceList=$apt_dir/sources.list" -o Dir::Etc::SourceParts=/dev/null
            -o "Dir::State::Lists=$apt_dir/lists" -o "Dir::Cache=$apt_dir/cache"
            -o APT::Sandbox::User=root)  # the private folders are not the _apt user's
  "${sudo_cmd[@]}" apt-get "${apt_opts[@]}" update
  "${sudo_cmd[@]}" mkdir -p "$tbb_source.partial"
  (cd "$tbb_source.partial" &&
     "${sudo_cmd[@]}" apt-get "${apt_opts[@]}" source --download-only "onetbb=$tbb_version" \
       >/dev/null 2>&1) || {
    echo "setup.sh: could not fetch Debian's source package onetbb=$tbb_version" >&2
    exit 1
  }
  "${sudo_cmd[@]}" rm -rf "$tbb_source"
  "${sudo_cmd[@]}" mv "$tbb_source.partial" "$tbb_source"
fi

if ((build)); then
  root=$(cd "$(dirname "$0")/.." && pwd)
  cmake -S "$root" -B "$root/build" -G Ninja -DCMAKE_BUILD_TYPE=Release
  cmake --build "$root/build"
fi
