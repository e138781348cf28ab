"""Arrays from Python are checked once, with a message naming the argument and the problem,
and a rejected call leaves the map as it was."""
import numpy as np
import pytest

import strata
from conftest import tree_digest, wall_scan

POINTS = wall_scan()
EYE = np.eye(4)


@pytest.mark.parametrize("points, pose, message", [
    (np.zeros((5, 2)), EYE, "points must have shape (N, 3); got (5, 2)"),
    (np.zeros(6), EYE, "points must have shape (N, 3); got (6,)"),
    (np.zeros((5, 3), dtype=np.int64), EYE, "points must be float32 or float64; got int64"),
    (POINTS, np.eye(3), "pose must have shape (4, 4) or (3, 4); got (3, 3)"),
    (POINTS, np.full((4, 4), np.nan), "pose has a NaN or infinite entry"),
    (POINTS, 2.0 * EYE, "the rotation part is not orthonormal"),
    (POINTS, np.diag([1.0, 1.0, -1.0, 1.0]), "the rotation part is not orthonormal"),
    (POINTS, np.vstack([EYE[:3], [0, 0, 1, 1]]), "the last row must be 0 0 0 1"),
])
def test_bad_points_and_poses_raise_invalid_argument_naming_the_problem(points, pose, message):
    m = strata.VoxelMap(0.2)
    with pytest.raises(strata.InvalidArgumentError, match=message.replace("(", r"\(")
                       .replace(")", r"\)")):
        m.integrate(points, pose)
    assert m.info()["observed_voxels"] == 0


def test_bad_labels_raise_invalid_argument_naming_the_problem():
    m = strata.VoxelMap(0.2)
    n = len(POINTS)
    with pytest.raises(strata.InvalidArgumentError, match=rf"labels must have shape \({n},\)"):
        m.integrate(POINTS, EYE, labels=np.zeros(n - 1, dtype=np.uint32))
    with pytest.raises(strata.InvalidArgumentError, match="labels must be integers; got float64"):
        m.integrate(POINTS, EYE, labels=np.zeros(n))
    with pytest.raises(strata.InvalidArgumentError, match="is not a label id"):
        m.integrate(POINTS, EYE, labels=np.full(n, -1))
    with pytest.raises(strata.InvalidArgumentError, match="is not a strata class"):
        m.integrate(POINTS, EYE, classes=np.full(n, 99))
    with pytest.raises(strata.InvalidArgumentError, match="not both"):
        m.integrate(POINTS, EYE, labels=np.zeros(n, np.uint32), classes=np.zeros(n, np.uint8))
    assert m.info()["observed_voxels"] == 0


def test_float32_float64_and_strided_points_give_the_same_map():
    kitti_like = np.hstack([POINTS, np.ones((len(POINTS), 1))]).astype(np.float32)
    maps = [strata.VoxelMap(0.2) for _ in range(3)]
    maps[0].integrate(POINTS.astype(np.float32), EYE)
    maps[1].integrate(POINTS.astype(np.float32).astype(np.float64), EYE)
    maps[2].integrate(kitti_like[:, :3], EYE)  # a column slice, read in place
    boxes = [m.voxels([-1, -5, -5], [12, 5, 5]) for m in maps]
    assert len(boxes[0]["log_odds"]) > 1000
    for other in boxes[1:]:
        for key in boxes[0]:
            np.testing.assert_array_equal(boxes[0][key], other[key])


def test_a_rejected_scan_leaves_the_stored_map_untouched(tmp_path, demo_scans):
    path = tmp_path / "map"
    with strata.Map.create(path, voxel=0.2) as m:
        with m.session("first") as s:
            s.integrate(demo_scans[0].points, demo_scans[0].pose, labels=demo_scans[0].labels)
        before = tree_digest(path)
        with pytest.raises(strata.InvalidArgumentError, match="NaN"):
            with m.session("bad") as s:
                s.integrate(demo_scans[1].points, demo_scans[1].pose)
                s.integrate(demo_scans[2].points, np.full((4, 4), np.nan))
        assert tree_digest(path) == before
        assert [s["name"] for s in m.sessions()] == ["first"]
