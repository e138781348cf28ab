"""KITTI 00 frames 0-5 integrated from numpy arrays vs `strata integrate` (issue 20; docs/bench.md,
Python).

    PYTHONPATH=build/python /usr/bin/python3 bench/bench_python.py STRATA DATA_DIR [--runs N]

Both sides do the same work on the same scans: create a map (voxel 0.2 m, 64 m tiles), one
session of frames 0-5 read from the .bin/.label files and integrated, commit. The program is
timed from its start to its exit (a separate process, as a user runs it); the module from
before Map.create to after the commit, reading the files with numpy included, the interpreter's
start and `import strata` not. Runs alternate; medians of N. CPU time (user + system) is steadier
than wall time on a shared machine. Prints markdown rows; exits non-zero when the module's
median wall time is more than 5 % above the program's (the target) or the maps differ, 77 when
KITTI 00 is missing (1 under STRATA_REQUIRE_DATA=1: measuring nothing is not a pass). Run by
hand (bench/run_benchmarks.sh), not in CI.
"""
import os
import pathlib
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import strata

TARGET = 1.05
FRAMES = range(6)


def children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run_program(strata_bin, sequence, out):
    cpu, start = children_cpu(), time.perf_counter()
    subprocess.run([strata_bin, "integrate", str(out), "--kitti", str(sequence), "--frames",
                    f"{FRAMES.start}:{FRAMES.stop}"], check=True, capture_output=True)
    return time.perf_counter() - start, children_cpu() - cpu


def run_module(sequence, out):
    cpu, start = time.process_time(), time.perf_counter()
    seq = strata.read_kitti(sequence)
    with strata.Map.create(out, voxel=0.2) as m:
        with m.session() as s:
            for i in FRAMES:
                points = np.fromfile(seq["scans"][i], dtype=np.float32).reshape(-1, 4)[:, :3]
                labels = np.fromfile(seq["labels"][i], np.uint32) if seq["labels"] else None
                s.integrate(points, seq["poses"][i], labels=labels)
    return time.perf_counter() - start, time.process_time() - cpu


def same_map(a, b) -> bool:
    box = ([-1e4] * 3, [1e4] * 3)
    with strata.Map.open(a, read_only=True) as ma, strata.Map.open(b, read_only=True) as mb:
        va, vb = ma.snapshot().voxels(*box), mb.snapshot().voxels(*box)
    return all(np.array_equal(va[k], vb[k]) for k in va)


def main() -> int:
    if len(sys.argv) < 3:
        print(__doc__, file=sys.stderr)
        return 2
    strata_bin, data = sys.argv[1], pathlib.Path(sys.argv[2])
    runs = int(sys.argv[sys.argv.index("--runs") + 1]) if "--runs" in sys.argv else 5
    sequence = data / "kitti00"
    if not (sequence / "velodyne").is_dir():
        required = os.environ.get("STRATA_REQUIRE_DATA") == "1"
        print(f"bench_python: {sequence} is absent; nothing measured", file=sys.stderr)
        return 1 if required else 77
    work = pathlib.Path(tempfile.mkdtemp(prefix="strata-bench-python-"))
    try:
        program, module = [], []
        for r in range(runs):
            order = [("program", program), ("module", module)]
            for name, times in (order if r % 2 == 0 else order[::-1]):
                out = work / name
                shutil.rmtree(out, ignore_errors=True)
                times.append(run_program(strata_bin, sequence, out) if name == "program"
                             else run_module(sequence, out))
        identical = same_map(work / "program", work / "module")
    finally:
        shutil.rmtree(work, ignore_errors=True)
    points = sum(len(np.fromfile(strata.read_kitti(sequence)["scans"][i], np.float32)) // 4
                 for i in FRAMES)
    wall = [statistics.median(t[0] for t in side) for side in (program, module)]
    cpu = [statistics.median(t[1] for t in side) for side in (program, module)]
    ratio = wall[1] / wall[0]
    print("| scans | points | `strata integrate` s | `strata.Map` from numpy s | module / program "
          "| program CPU s | module CPU s | CPU ratio | same map |")
    print("|---|---|---|---|---|---|---|---|---|")
    print(f"| {len(FRAMES)} | {points} | {wall[0]:.3f} | {wall[1]:.3f} | {ratio:.3f} "
          f"| {cpu[0]:.3f} | {cpu[1]:.3f} | {cpu[1] / cpu[0]:.3f} | {'yes' if identical else 'NO'} |")
    print()
    print(f"KITTI 00 frames 0-5, voxel 0.2 m, 64 m tiles, TBB threads: all of {os.cpu_count()}; "
          f"medians of {runs} alternating runs; maps under {tempfile.gettempdir()}.")
    if not identical:
        print("bench_python: the maps differ", file=sys.stderr)
        return 1
    if ratio > TARGET:
        print(f"bench_python: the module took {ratio:.3f}x the program's time "
              f"(target <= {TARGET})", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
