#!/usr/bin/env bash
# Runs the benchmarks and rewrites docs/bench.md with the date, commit and CPU.
# Usage: bench/run_benchmarks.sh [BUILD_DIR]   (default build/; needs ../shared/data)
# Every benchmark runs even when one misses a target (or finds no data: exit 77), so that the
# page shows all of them; the script then names each that failed and exits 1.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
out=$root/docs/bench.md
cpu=$(lscpu | sed -n 's/^Model name:[[:space:]]*//p' | head -n1)
failed=()
Bench() {  # Bench NAME COMMAND...: runs it; a non-zero exit is noted on the page and kept.
  local name=$1 status=0
  shift
  "$@" || status=$?
  if ((status != 0)); then
    echo
    echo "**$name exited $status: a target was missed or data was missing (see above).**"
    failed+=("$name (exit $status)")
  fi
}
SimTable() {  # bench_sim's table as a code block; the status is bench_sim's (misses: stderr)
  local status=0
  echo '```'
  "$build/bench/bench_sim" --benchmark_min_time=1 | grep -v '^\*\*\*' || status=$?
  echo '```'
  return $status
}
{
  echo "# Benchmarks"
  echo
  echo "Measured $(date -u +%Y-%m-%d) on commit \`$(git -C "$root" rev-parse --short HEAD)\`,"
  echo "CPU: $cpu, $(nproc) cores, $(free -g | awk '/Mem:/{print $2}') GiB RAM (a shared virtual machine: expect"
  echo "run-to-run noise of 10-20 %). Regenerate with \`bench/run_benchmarks.sh\`."
  echo
  echo "## Integration: strata vs OctoMap 1.9.7 (\`bench/bench_integration\`)"
  echo
  echo "Same float points, same process, max range 50 m. OctoMap: \`OcTree::insertPointCloud\`"
  echo "(compiled without OpenMP, i.e. one thread). strata: \`Integrator::Integrate\` with TBB limited"
  echo "to 1 and 2 threads. Memory: \`OcTree::memoryUsage()\` vs the sum of \`memUsage()\` of the map's"
  echo "grids (occupancy, label, label_weight, endpoints). Jaccard: occupied and free voxel sets, OctoMap's"
  echo "pruned nodes expanded to voxels; \"voxels differing\": every voxel of both maps compared, state and"
  echo "log-odds (1e-5), and the program exits 1 if any differs, or when a row misses the one documented:"
  echo "speed-up or two-thread ratio under its value / 2.5, memory ratio above its value. Targets"
  echo "(issues 2 and 19) and where the time and bytes go: [integration.md, Speed and"
  echo "Memory](integration.md#speed)."
  echo
  Bench bench_integration "$build/bench/bench_integration" "$root/../shared/data"
  echo
  echo "Short run (\`bench_integration --ci\`, CTest \`BenchIntegrationCi\`, label \`bench\`: speed-ups"
  echo "and memory held at 0.2 and 0.1 m, two-thread ratios printed, not judged):"
  echo
  Bench "bench_integration --ci" "$build/bench/bench_integration" "$root/../shared/data" --ci
  if [[ -x "$build/bench/bench_store" ]]; then
    echo
    echo "## Store"
    echo
    echo "\`bench/bench_store\` (format 5, issue 17): BALM (89 scans, voxel 0.2 m, default"
    echo "\`IntegrationConfig\`, all cores) integrated into one in-memory \`VoxelMap\` with"
    echo "\`Integrator\` vs into a map on disk with \`store::SessionWriter\` and \`Commit\` (fused"
    echo "file + the session's layer file per touched tile, fsync'd), as one session and as 5"
    echo "sessions of consecutive scans, with 64 m (default) and 16 m tiles. Overhead: median over"
    echo "runs of store / in-memory time of the same run; CPU overhead: the same in process CPU"
    echo "time, steadier on a shared machine, and the one the target judges (5 sessions, 64 m: at"
    echo "most +20 %). Then one session under a memory budget of a quarter of the unbudgeted peak,"
    echo "compared tile by tile with the unbudgeted map; what a reader pays to open a map, take"
    echo "the newest snapshot and read the tile under the first scan (median of 20). Then KITTI"
    echo "00's six frames integrated as the same session again and again (sessions 1..50, 64 m"
    echo "tiles): bytes and time of each commit (targets: session 50 <= 1.1x the bytes and 1.2x"
    echo "the CPU time of session 2, medians of three sessions for time; disk growth linear), a"
    echo "whole read of the 50-session map by bytes read per kind (target: no layer byte), and"
    echo "a 10-session map rewritten as format 4 and migrated (target: every snapshot and layer"
    echo "identical, \`check\` clean). The program exits non-zero when a target is missed; CTest"
    echo "runs \`bench_store --short\` (12 sessions of two frames, one repetition). Design and"
    echo "guarantees: [store.md](store.md)."
    echo
    Bench bench_store "$build/bench/bench_store" "$root/../shared/data"
  fi
  if [[ -x "$build/bench/bench_change" ]]; then
    echo
    echo "## Change detection (\`bench/bench_change\`)"
    echo
    echo "BALM (89 scans, voxel 0.2 m) in a map on disk as two sessions (scans 0-44, 45-88)."
    echo "A whole-map change query: read both sides from the store (tile files verified and"
    echo "decoded; a file shared by both sides read once), then \`DetectChanges\` (topology"
    echo "operations and grouping). Target: well under a second; the program exits 1 when a query takes"
    echo "0.5 s or more (by hand, not in CI). Semantics: [change.md](change.md)."
    echo
    Bench bench_change "$build/bench/bench_change" "$root/../shared/data"
  fi
  if [[ -x "$build/bench/bench_walls" ]]; then
    echo
    echo "## Walls (\`bench/bench_walls\`)"
    echo
    echo "\`walls::FindWalls\` with default settings on maps integrated in memory (outside the"
    echo "timing), TBB limited to one thread. Target: a BALM-sized map in a few seconds on one"
    echo "core; the program exits 1 when a BALM row takes more than 5 s (by hand, not in CI). Pipeline"
    echo "and accuracy: [walls.md](walls.md)."
    echo
    Bench bench_walls "$build/bench/bench_walls" "$root/../shared/data"
  fi
  if [[ -x "$build/bench/bench_vehicles" ]]; then
    echo
    echo "## Vehicles (\`bench/bench_vehicles\`)"
    echo
    echo "Accuracy of \`vehicles::ClearVehicles\` on the simulated garage (the table of"
    echo "[vehicles.md](vehicles.md)), then its time on real maps integrated in memory (outside the"
    echo "timing), with all cores and with TBB limited to one. Target: a BALM-sized map in a few"
    echo "seconds."
    echo
    Bench bench_vehicles "$build/bench/bench_vehicles" "$root/../shared/data"
  fi
  if [[ -x "$build/bench/bench_registration" ]]; then
    echo
    echo "## Registration (\`bench/bench_registration\`)"
    echo
    echo "One core (TBB limited to 1), maps integrated in memory outside the timing. First table:"
    echo "time per registration with its error (KITTI 00 against the raw-point optimum of"
    echo "[registration.md](registration.md#real-scans-strata-against-the-raw-point-optimum), BALM's"
    echo "second half against its unmoved alignment composed with the known move, the building"
    echo "against the simulator's poses). Second table: every real pair, strata"
    echo "(map of scan A, scan B from 0.5 m / 3 deg off) with 6000 and with 20000 (the default)"
    echo "source points at the finest level beside the plain raw-point ICP it is measured"
    echo "against; the program exits 1 when a pair misses 0.05 deg."
    echo
    Bench bench_registration "$build/bench/bench_registration" "$root/../shared/data" --repeat 3
  fi
  if [[ -x "$build/bench/bench_viewer" ]]; then
    echo
    echo "## Viewer (\`bench/bench_viewer\`, \`bench/bench_viewer_page.py\`)"
    echo
    echo "\`strata view\` (issue 21). First, one tile answer of BALM at 0.1 m in 64 m tiles at each"
    echo "level of detail, step by step and over HTTP, cold (a server without caches: the tile"
    echo "file is read, verified and decoded whole) and as \`strata view\` serves it (tiles read"
    echo "at start and kept; the cache of finished answers off). Target: median under 50 ms."
    echo "Then the first picture in headless Chromium (SwiftShader) of BALM at 0.2 m and of ten"
    echo "copies of it side by side, from navigation start; target under 2 s, the same for the"
    echo "10x map, which sends only the tiles in view. Both programs exit 1 on a miss (by hand, not"
    echo "in CI). Design: [viewer.md](viewer.md)."
    echo
    maps=$(mktemp -d)
    trap 'rm -rf "$maps"' EXIT
    Bench bench_viewer "$build/bench/bench_viewer" "$root/../shared/data" --keep "$maps"
    echo
    Bench bench_viewer_page.py \
      /usr/bin/python3 "$root/bench/bench_viewer_page.py" "$build/tools/strata/strata" "$maps"
    rm -rf "$maps"
  fi
  if compgen -G "$build/python/strata/_strata*.so" >/dev/null; then
    echo
    echo "## Python (\`bench/bench_python.py\`)"
    echo
    echo "KITTI 00 frames 0-5 into a new map (voxel 0.2 m) from numpy arrays with \`strata.Map\`"
    echo "vs \`strata integrate --kitti --frames 0:6\` on the same files: the program timed from"
    echo "start to exit, the module from \`Map.create\` to the commit with the files read by numpy."
    echo "Target (issue 20): the module within 5 % of the program; the script exits 1 on a miss (by"
    echo "hand, not in CI). Usage: [python.md](python.md)."
    echo
    Bench bench_python.py env PYTHONPATH="$build/python" /usr/bin/python3 \
      "$root/bench/bench_python.py" "$build/tools/strata/strata" "$root/../shared/data"
  fi
  if [[ -x "$build/bench/bench_sim" ]]; then
    echo
    echo "## Simulator (\`bench/bench_sim\`)"
    echo
    echo "Full sweeps on one core over the example scenes; target 5 M rays per second per core for every"
    echo "sweep, and the program exits 1 when the median of one falls below it (by hand, not in CI)."
    echo "[simulator.md](simulator.md#speed)."
    echo
    Bench bench_sim SimTable
  fi
} > "$out.tmp"
mv "$out.tmp" "$out"
echo "wrote $out"
if ((${#failed[@]} > 0)); then
  printf 'run_benchmarks.sh: failed: %s\n' "${failed[@]}" >&2
  exit 1
fi
