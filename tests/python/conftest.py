"""Shared fixtures of the Python module's tests: small simulated scans, the strata program,
the source tree and the real data (tests that need it skip with a message when it is absent;
under STRATA_REQUIRE_DATA=1, as CI sets it, every skip is a failure: pytest runs as one CTest
test, `python_pytest`, which passes whatever pytest skipped, so nothing else would see it)."""
import hashlib
import os
import pathlib
import subprocess

import numpy as np
import pytest

import strata

SOURCE_DIR = pathlib.Path(os.environ.get("STRATA_SOURCE_DIR",
                                         pathlib.Path(__file__).resolve().parents[2]))
DATA_DIR = pathlib.Path(os.environ.get("STRATA_DATA_DIR", SOURCE_DIR.parent / "shared" / "data"))
STRATA = os.environ.get("STRATA_BINARY", str(SOURCE_DIR / "build" / "tools" / "strata" / "strata"))
STREET = SOURCE_DIR / "datasets" / "scenes" / "street.json"
# Missing real data fails instead of skipping (tests/support/RealData.hpp does the same in C++).
REQUIRE_DATA = os.environ.get("STRATA_REQUIRE_DATA") == "1"


def skip_without_data(path):
    """Skips the calling test when the real data at `path` is absent: a failure under
    STRATA_REQUIRE_DATA=1."""
    if pathlib.Path(path).exists():
        return
    if REQUIRE_DATA:
        pytest.fail(f"real data not found: {path} (STRATA_REQUIRE_DATA=1; "
                    "see ../shared/data/README.md)")
    pytest.skip(f"real data not found: {path} (see ../shared/data/README.md)")


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    """Under STRATA_REQUIRE_DATA=1 any skip fails its test, whatever called pytest.skip: CI
    must not pass on a smaller suite."""
    outcome = yield
    report = outcome.get_result()
    if REQUIRE_DATA and report.skipped and not hasattr(report, "wasxfail"):
        reason = report.longrepr[2] if isinstance(report.longrepr, tuple) else report.longrepr
        report.outcome = "failed"
        report.longrepr = f"skipped under STRATA_REQUIRE_DATA=1, which allows no skip: {reason}"


@pytest.hookimpl(hookwrapper=True)
def pytest_make_collect_report(collector):
    """The same for a whole module skipped while it is collected."""
    outcome = yield
    report = outcome.get_result()
    if REQUIRE_DATA and report.skipped:
        reason = report.longrepr[2] if isinstance(report.longrepr, tuple) else report.longrepr
        report.outcome = "failed"
        report.longrepr = f"skipped under STRATA_REQUIRE_DATA=1, which allows no skip: {reason}"


def run_strata(*args, cwd=None) -> subprocess.CompletedProcess:
    """Runs the strata program; fails the test with its stderr when it fails."""
    done = subprocess.run([STRATA, *map(str, args)], capture_output=True, text=True, cwd=cwd)
    assert done.returncode == 0, f"strata {' '.join(map(str, args))}: {done.stderr}"
    return done


def tree_digest(path) -> dict:
    """Every file under `path` with its SHA-256, but what readers touch without changing the
    map: the writer's lock, SQLite's shared-memory index (-shm) and an empty write-ahead log."""
    root = pathlib.Path(path)

    def content(p):
        return not (p.name == "writer.lock" or p.name.endswith("-shm") or
                    (p.name.endswith("-wal") and p.stat().st_size == 0))
    return {str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(root.rglob("*")) if p.is_file() and content(p)}


@pytest.fixture(scope="session")
def demo_scans():
    """Three scans of the simulator's built-in street, with SemanticKITTI labels."""
    return list(strata.simulate("demo", max_scans=3))


@pytest.fixture(scope="session")
def street_sequence(tmp_path_factory):
    """Four scans of datasets/scenes/street.json as `strata simulate` writes them."""
    out = tmp_path_factory.mktemp("street") / "seq"
    run_strata("simulate", "--scene", STREET, "--out", out, "--max-scans", 4, "--no-picture")
    return out


def kitti_scans(sequence, frames=None):
    """The scans of a KITTI folder as a numpy user reads them: points, labels and poses."""
    seq = strata.read_kitti(sequence)
    indices = range(len(seq["scans"])) if frames is None else frames
    for i in indices:
        points = np.fromfile(seq["scans"][i], dtype=np.float32).reshape(-1, 4)[:, :3]
        labels = np.fromfile(seq["labels"][i], dtype=np.uint32) if seq["labels"] else None
        yield points, seq["poses"][i], labels


def wall_scan(distance=10.0, half_width=4.0, height=3.0, spacing=0.05):
    """Points of a flat wall `distance` metres ahead (x) of a sensor at the origin, 4 m wide
    (y in [-2, 2] by default) and `height` m tall from z = -1."""
    y, z = np.meshgrid(np.arange(-half_width / 2, half_width / 2, spacing),
                       np.arange(-1.0, -1.0 + height, spacing))
    return np.stack([np.full(y.size, distance), y.ravel(), z.ravel()], axis=1)
