"""Map.localize: a scan of a storey found in the slice of a stacked building, with the keys and
values `strata localize --json` reports on the same map and scan; bad input is refused with a
clear message and the map is only read."""
import json

import numpy as np
import pytest

import strata
from conftest import SOURCE_DIR, run_strata, tree_digest

BUILDING = SOURCE_DIR / "datasets" / "scenes" / "building.json"
LOCALIZE_TOLERANCE_M = 0.05  # issue 8's localization target
TIMES = ("time_ms", "surface_ms", "total_ms")  # run times differ from run to run
FRAME = 6


def yaw_deg(T):
    return float(np.degrees(np.arctan2(T[1, 0], T[0, 0])))


@pytest.fixture(scope="module")
def building(tmp_path_factory):
    """building.json's ground floor and first floor (40 scans each: the whole corridor) as two
    sessions in their own frames, floor 1 stacked on floor 0 from the z-bias by the program.
    Returns the folder, the scan file of floor 1's frame 6, its points and its true pose in the
    map frame (the stacked floor's frame times the scan's pose)."""
    work = tmp_path_factory.mktemp("building")
    run_strata("simulate", "--scene", BUILDING, "--out", work / "seq", "--max-scans", 40,
               "--no-picture")
    for k in range(2):
        run_strata("integrate", work / "map", "--voxel", 0.1, "--kitti",
                   work / "seq" / f"session_{k}", "--name", f"floor_{k}")
    out = run_strata("stack", work / "map", "--floor-session", "floor_1", "--z-bias", 3.5,
                     "--z-bias-only", "--json").stdout
    T_map_floor = np.array(json.loads(out[out.index("{"):])["T"]).reshape(4, 4)
    seq = strata.read_kitti(work / "seq" / "session_1")
    scan = seq["scans"][FRAME]
    points = np.fromfile(scan, np.float32).reshape(-1, 4)[:, :3]
    return work / "map", scan, points, T_map_floor @ seq["poses"][FRAME]


def guess_near(truth):
    """(x, y, z, yaw_deg) 0.3 m and 3 degrees from `truth`."""
    x, y, z = truth[:3, 3] + [0.2, -0.2, 0.05]
    return (float(x), float(y), float(z), yaw_deg(truth) + 3.0)


def test_localize_finds_the_scan_and_equals_strata_localize_json(building):
    path, scan, points, truth = building
    init = guess_near(truth)
    out = run_strata("localize", path, "--scan", scan, "--floor", 1, "--json", "--init",
                     ",".join(f"{v:.6f}" for v in init)).stdout
    theirs = json.loads(out[out.index("{"):])
    before = tree_digest(path)
    with strata.Map.open(path, read_only=True) as m:
        ours = m.localize(points, 1, init=[round(v, 6) for v in init])
    pose = ours.pop("pose")
    assert ours["converged"], ours["refusal"]
    assert np.linalg.norm(pose[:3, 3] - truth[:3, 3]) < LOCALIZE_TOLERANCE_M
    np.testing.assert_allclose(np.array(ours["T"]).reshape(4, 4), pose)
    for report in (ours, theirs):
        for key in TIMES:
            report.pop(key)
    assert ours == theirs
    assert ours["floor"] == 1
    assert tree_digest(path) == before


def test_localize_refuses_bad_input_and_leaves_the_map(building):
    path, _, points, truth = building
    before = tree_digest(path)
    with strata.Map.open(path, read_only=True) as m:
        with pytest.raises(strata.InvalidArgumentError, match="--floor 4: .* 2 floors recorded"):
            m.localize(points, 4)
        with pytest.raises(strata.InvalidArgumentError, match="floor must be a storey index"):
            m.localize(points, "first")
        with pytest.raises(strata.InvalidArgumentError, match=r"points must have shape \(N, 3\)"):
            m.localize(points[:, :2], 1)
        with pytest.raises(strata.InvalidArgumentError, match="init must be finite"):
            m.localize(points, 1, init=(np.nan, 0.0, 0.0, 0.0))
        with pytest.raises(strata.InvalidArgumentError, match="l1"):
            m.localize(points, 1, l1=3.0, l2=1.0)
        far = m.localize(points, 1, init=(truth[0, 3] + 60.0, truth[1, 3], truth[2, 3], 0.0))
    assert not far["converged"] and far["refusal"]  # refused on its merits: returned, not raised
    assert tree_digest(path) == before
