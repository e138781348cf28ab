#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan) in build-fuzz/, writes their seed
# corpora and runs each target for a while; fails when any target finds a crash, a sanitizer
# report, a hang (-timeout) or runaway memory (-rss_limit_mb). docs/reliability.md, "Fuzzing".
# Usage: tools/fuzz.sh [SECONDS_PER_TARGET]   (default 20)
#   STRATA_FUZZ_TARGETS="pcd ply"  only these targets     STRATA_BUILD_JOBS=2  build parallelism
#   STRATA_FUZZ_JOBS=1  targets run at once (default: one per core)
# Corpora grow in build-fuzz/corpus/<target>/ across runs; crash inputs land in
# build-fuzz/artifacts/, each target's output in build-fuzz/logs/<target>.log.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
seconds=${1:-20}
build="$root/build-fuzz"
targets=(${STRATA_FUZZ_TARGETS:-kitti bin pcd ply las text text_bz2 poses scene map catalog recording})

# Largest input per target: a few records beyond the seeds, small enough to mutate quickly.
declare -A max_len=([kitti]=1024 [bin]=1024 [pcd]=4096 [ply]=4096 [las]=4096 [text]=2048
                    [text_bz2]=2048 [poses]=2048 [scene]=8192 [map]=81920
                    [catalog]=131072 [recording]=16384)

command -v clang++ >/dev/null || { echo "fuzz.sh: clang++ not found (tools/setup.sh installs it)" >&2; exit 1; }
start=$(date +%s)
# Tests and tools are configured (not built) so that tools/sanitize.sh asan, which builds and
# runs them here, shares every object with this script: keep the two configurations equal.
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_COMPILER=clang++ -DSTRATA_BUILD_FUZZ=ON -DSTRATA_BUILD_TESTS=ON \
  -DSTRATA_BUILD_TOOLS=ON -DSTRATA_BUILD_BENCH=OFF >/dev/null
cmake --build "$build" -j "${STRATA_BUILD_JOBS:-$(nproc)}" --target fuzz
echo "fuzz.sh: build took $(($(date +%s) - start)) s"

rm -rf "$build/seeds"
"$build/tests/fuzz/fuzz_make_corpus" "$build/seeds"
# Seed recordings by independent writers (tools/setup.sh installs them): ROS 1 bags by Debian's
# python3-rosbag, MCAP files by @mcap/core, in each compression, and a rosbag2 .db3 by Python's
# sqlite3 from @foxglove/rosmsg2-serialization's CDR, with per-point times and poses denser than
# the sweeps.
mkdir -p "$build/seeds/recording"
for c in none bz2 lz4; do
  /usr/bin/python3 "$root/tests/recordings/write_ros1_bag.py" "$build/seeds/_recording_seq" \
    "$build/seeds/recording/$c.bag" --compression "$c" --chunk-kb 1 --point-time t --tf-rate 3
done
for c in none lz4 zstd; do
  NODE_PATH="$root/build-deps/npm/node_modules" node "$root/tests/recordings/write_mcap.mjs" \
    "$build/seeds/_recording_seq" "$build/seeds/recording/$c.mcap" --compression "$c" \
    --chunk-kb 1 --point-time t --tf-rate 3
done
NODE_PATH="$root/build-deps/npm/node_modules" node "$root/tests/recordings/write_mcap.mjs" \
  "$build/seeds/_recording_seq" "$build/seeds/_recording.mcap" --point-time t --tf-rate 3 \
  --dump "$build/seeds/_recording_cdr"
/usr/bin/python3 "$root/tests/recordings/write_db3.py" "$build/seeds/_recording_cdr" \
  "$build/seeds/_recording_db3"
# 512-byte pages (VACUUM by the same sqlite3) bring it from 20 KB to 5 KB, under max_len.
/usr/bin/python3 -c 'import sqlite3, sys; c = sqlite3.connect(sys.argv[1], isolation_level=None)
c.execute("PRAGMA page_size=512"); c.execute("VACUUM")' "$build/seeds/_recording_db3/bag_0.db3"
cp "$build/seeds/_recording_db3/bag_0.db3" "$build/seeds/recording/bag.db3"
mkdir -p "$build/corpus" "$build/artifacts" "$build/logs"

# Leak checking is off: OpenVDB and TBB keep process-lifetime allocations that are not bugs.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1}
# Each target runs on one core for SECONDS; as many run at once as there are cores
# (STRATA_FUZZ_JOBS), so a target's search is the same as alone and the step takes a share of
# the time.
parallel=${STRATA_FUZZ_JOBS:-$(nproc)}
Fuzz() {  # Fuzz TARGET: runs it; its log in logs/, its verdict in logs/TARGET.result.
  local t=$1 corpus="$build/corpus/$1" log="$build/logs/$1.log" result=ok
  mkdir -p "$corpus"
  local dirs=("$corpus" "$build/seeds/$t")
  [[ -d "$root/tests/fuzz/seeds/$t" ]] && dirs+=("$root/tests/fuzz/seeds/$t")
  "$build/tests/fuzz/fuzz_$t" -max_total_time="$seconds" -max_len="${max_len[$t]}" \
    -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 \
    -artifact_prefix="$build/artifacts/$t-" "${dirs[@]}" >"$log" 2>&1 || result=FAILED
  echo "$result" >"$build/logs/$t.result"
}
for t in "${targets[@]}"; do
  rm -f "$build/logs/$t.result"
  while (($(jobs -rp | wc -l) >= parallel)); do wait -n || true; done
  Fuzz "$t" &
done
wait
failed=()
printf '%-9s %8s %12s %8s  %s\n' target seconds execs corpus result
for t in "${targets[@]}"; do
  log="$build/logs/$t.log"
  result=$(cat "$build/logs/$t.result" 2>/dev/null || echo FAILED)
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  printf '%-9s %8s %12s %8s  %s\n' "$t" "$seconds" "${execs:-?}" \
    "$(find "$build/corpus/$t" -type f | wc -l)" "$result"
  if [[ $result != ok ]]; then
    failed+=("$t")
    grep -m3 -E 'ERROR: |runtime error|SUMMARY' "$log" | sed 's/^/    /' || true
  fi
done
echo "fuzz.sh: total $(($(date +%s) - start)) s"
if ((${#failed[@]})); then
  echo "fuzz.sh: crashes in: ${failed[*]} (inputs in $build/artifacts, logs in $build/logs)" >&2
  exit 1
fi
