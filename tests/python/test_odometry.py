"""A session with odometry=True: scans without poses, posed by LiDAR odometry as
`strata integrate --odometry` poses them (docs/odometry.md), on the simulator's district drive
with a sweep every metre."""
import numpy as np
import pytest

import strata
from conftest import SOURCE_DIR

# Measured on 2026-12-05: the poses lie within 0.112 m of the drive's over its first 19 m (as
# `strata odometry` writes them, tests/tools/TestOdometryCli.cpp); held at about 2x.
MAX_POSITION_ERROR_M = 0.25
# The drive's sensor is level over level ground: the first scan's ground plane finds it tilted by
# 0.0011 deg (2026-12-05); held at about 3x.
MAX_TILT_DEG = 0.003


def district_drive(tmp_path, scans):
    """The first `scans` sweeps of the small district's survey drive, one a metre (the scene
    file has one every 10 m)."""
    text = (SOURCE_DIR / "datasets" / "scenes" / "district_small.json").read_text()
    assert '"every": 10' in text
    scene = tmp_path / "district_every_metre.json"
    scene.write_text(text.replace('"every": 10', '"every": 1', 1))
    return list(strata.simulate(scene, max_scans=scans))


def test_a_session_with_odometry_maps_scans_without_poses(tmp_path):
    scans = district_drive(tmp_path, 20)
    with strata.Map.create(tmp_path / "drive.strata", voxel=0.2) as m:
        with m.session("drive", odometry=True) as s:
            assert s.gravity is None  # no scan yet
            for scan in scans:
                s.integrate(scan)  # its pose is not used
            poses = s.poses
            gravity = s.gravity
        assert [r["scans"] for r in m.sessions()] == [20]
    assert poses.shape == (20, 4, 4)
    first = np.linalg.inv(scans[0].pose)
    errors = [np.linalg.norm(poses[k][:3, 3] - (first @ scan.pose)[:3, 3])
              for k, scan in enumerate(scans)]
    assert max(errors) < MAX_POSITION_ERROR_M
    assert gravity["source"] == "ground_plane", gravity
    assert gravity["tilt_deg"] < MAX_TILT_DEG and gravity["points"] > 1000, gravity
    assert abs(gravity["height_m"] - 1.73) < 0.01, gravity  # the scene's sensor height


def test_a_scan_the_odometry_cannot_register_leaves_the_map_as_it_was(tmp_path):
    scans = district_drive(tmp_path, 5)
    with strata.Map.create(tmp_path / "refused.strata", voxel=0.2) as m:
        with pytest.raises(strata.RefusedError, match="scan 2 .*too little overlap"):
            with m.session("drive", odometry=True) as s:
                for k, scan in enumerate(scans):
                    moved = np.asarray(scan.points, np.float64) + (300.0 if k == 2 else 0.0)
                    s.integrate(moved)
        assert m.sessions() == []
        s = m.session("posed", odometry=True)
        with pytest.raises(strata.InvalidArgumentError, match="without a pose"):
            s.integrate(scans[0].points, scans[0].pose)
        s.abort()
        assert m.sessions() == []
