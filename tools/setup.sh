#!/usr/bin/env bash
# Installs strata's build dependencies from Debian 12 packages (idempotent; run as root or with sudo).
# Usage: tools/setup.sh                install only
#        tools/setup.sh --build        install, then build the `strata` program into build/
#        tools/setup.sh --python       install, then build the program and the Python module
#        tools/setup.sh --sanitizers   install, and fetch the source of libtbb for
#                                      tools/sanitize.sh tsan (.ci/run does)
set -euo pipefail
build=0
python=0
sanitizers=0
for arg in "$@"; do
  case $arg in
    --build) build=1 ;;
    --python) build=1 python=1 ;;
    --sanitizers) sanitizers=1 ;;
    *) echo "usage: tools/setup.sh [--build] [--python] [--sanitizers]" >&2; exit 2 ;;
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
  clang-format              # tools/format.sh (.ci/run checks the formatting)
  libopenmpi-dev openmpi-bin              # mpirun strata ... (docs/scale.md)
  pybind11-dev python3-dev python3-numpy  # the Python module (python/, docs/python.md)
  python3-matplotlib                      # docs/python.md's plotting example (tested)
  groff-base                              # the install test reads the man pages (groff)
  liblz4-dev libzstd-dev zlib1g-dev       # recordings' chunks and CRCs (src/recordings/)
  # An independent writer of the test recordings: ROS 1 bags by rosbag (tests/recordings/).
  python3-rosbag python3-roslz4 python3-sensor-msgs python3-tf2-msgs python3-nav-msgs
  python3-geometry-msgs
  nodejs lz4 zstd  # and MCAP files by @mcap/core (below), chunks compressed by lz4 and zstd
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

# The independent writers of the MCAP test recordings (tests/recordings/write_mcap.mjs) and the
# independent reader of exported PCD files (tests/io/read_pcd.mjs), from the machine's npm
# registry into the ignored build-deps/npm/ (tests set NODE_PATH there). Pinned by major version;
# installed once.
npm_dir="$(cd "$(dirname "$0")/.." && pwd)/build-deps/npm"
if [[ ! -d $npm_dir/node_modules/@mcap/core || ! -d $npm_dir/node_modules/@foxglove/rosmsg ||
      ! -d $npm_dir/node_modules/@foxglove/rosmsg2-serialization ||
      ! -d $npm_dir/node_modules/@loaders.gl/pcd || ! -d $npm_dir/node_modules/@loaders.gl/core ]]; then
  if ! command -v npm >/dev/null; then
    sudo_cmd=()
    [[ $(id -u) -eq 0 ]] || sudo_cmd=(sudo)
    DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends npm
  fi
  mkdir -p "$npm_dir"
  npm install --prefix "$npm_dir" --no-audit --no-fund --loglevel=error \
    @mcap/core@2 @foxglove/rosmsg2-serialization@3 @foxglove/rosmsg@5 @loaders.gl/core@4 \
    @loaders.gl/pcd@4
fi

# The source package of the installed libtbb, for tools/sanitize.sh tsan: ThreadSanitizer needs
# a libtbb built with it (docs/reliability.md, "Sanitizers"). Fetched here, with the packages, so
# that builds never download; apt-get checks the files against the signed index of the machine's
# own archives. A private source list and state keep the machine's apt configuration untouched.
#
# DebSrcEntries: the machine's apt sources (one-line .list files and deb822 .sources files, at
# the places apt-config names) as source entries: `deb ...` becomes `deb-src ...`, `Types: deb`
# becomes `Types: deb-src`. Options, signing keys, suites and components stay as they are.
DebSrcEntries() {
  local out=$1 list parts f
  eval "$(apt-config shell list Dir::Etc::SourceList/f parts Dir::Etc::SourceParts/d)"
  mkdir -p "$out"
  for f in "$list" "$parts"*.list; do
    [[ -f $f ]] || continue
    sed -n -E 's/^[[:space:]]*deb([[:space:]]+)/deb-src\1/p' "$f" >>"$out/sources.list"
  done
  for f in "$parts"*.sources; do
    [[ -f $f ]] || continue
    # A stanza whose Types lack deb (deb-src only) is dropped: its lines are kept only when the
    # stanza, read to its blank line, had `deb` among its types.
    awk 'function flush() { if (keep) printf "%s", stanza; stanza = ""; keep = 0 }
         /^[[:space:]]*$/ { flush(); print ""; next }
         tolower($1) == "types:" {
           for (i = 2; i <= NF; i++) if ($i == "deb") keep = 1
           stanza = stanza "Types: deb-src\n"; next }
         { stanza = stanza $0 "\n" }
         END { flush() }' "$f" >"$out/$(basename "$f")"
  done
}

tbb_version=$(dpkg-query -W -f='${Version}' libtbb-dev)
tbb_source=${STRATA_TBB_SOURCE_DIR:-/var/cache/strata/onetbb-$tbb_version}
if ((sanitizers)) && ! compgen -G "$tbb_source/onetbb_*.dsc" >/dev/null; then
  sudo_cmd=()
  [[ $(id -u) -eq 0 ]] || sudo_cmd=(sudo)
  apt_dir=$(mktemp -d)
  trap 'rm -rf "$apt_dir"' EXIT
  mkdir -p "$apt_dir/lists/partial" "$apt_dir/cache/archives/partial"
  DebSrcEntries "$apt_dir/sources"
  apt_opts=(-qq -o "Dir::Etc::SourceList=$apt_dir/sources/sources.list"
            -o "Dir::Etc::SourceParts=$apt_dir/sources"
            -o "Dir::State::Lists=$apt_dir/lists" -o "Dir::Cache=$apt_dir/cache"
            -o APT::Sandbox::User=root)  # the private folders are not the _apt user's
  "${sudo_cmd[@]}" apt-get "${apt_opts[@]}" update
  "${sudo_cmd[@]}" mkdir -p "$tbb_source.partial"
  (cd "$tbb_source.partial" &&
     "${sudo_cmd[@]}" apt-get "${apt_opts[@]}" source --download-only "onetbb=$tbb_version" \
       >/dev/null 2>&1) || {
    echo "setup.sh: could not fetch Debian's source package onetbb=$tbb_version from the" \
         "machine's apt sources (as deb-src entries: $apt_dir/sources)" >&2
    trap - EXIT  # keep them for the user to look at
    exit 1
  }
  "${sudo_cmd[@]}" rm -rf "$tbb_source"
  "${sudo_cmd[@]}" mv "$tbb_source.partial" "$tbb_source"
fi

# The `strata` program (with --python also the Python module, when configured:
# python/CMakeLists.txt) and what they need, in build/ as tools/test.sh configures it (same
# settings, ccache), so the test command afterwards compiles only the rest. The module is left
# to --python and to the test command: the quick start's first picture does not wait for it.
if ((build)); then
  root=$(cd "$(dirname "$0")/.." && pwd)
  "$root/tools/configure.sh"
  targets=(strata)
  ((python)) && [[ -d $root/build/python/strata ]] && targets+=(_strata)
  cmake --build "$root/build" --target "${targets[@]}"
fi
