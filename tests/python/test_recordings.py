"""read_bag: a recording's sweeps, posed and deskewed, on ROS 1 bags written by Debian's
python3-rosbag (tests/recordings/write_ros1_bag.py, an independent writer)."""
import subprocess

import numpy as np
import pytest

import strata
from conftest import SOURCE_DIR, run_strata

WRITER = SOURCE_DIR / "tests" / "recordings" / "write_ros1_bag.py"


def kitti_folder(path, scans=3):
    """Three scans of a 6 x 4 x 3 m box, 0.5 m apart along x, as a KITTI-layout folder."""
    rng = np.random.default_rng(3)
    (path / "velodyne").mkdir(parents=True)
    poses = []
    for k in range(scans):
        d = rng.uniform(-1, 1, (2000, 3))
        points = d * (np.array([3.0, 2.0, 1.5]) / np.abs(d)).min(axis=1, keepdims=True)
        cloud = np.hstack([points, rng.uniform(0, 1, (2000, 1))]).astype(np.float32)
        cloud.tofile(path / "velodyne" / f"{k:06d}.bin")
        pose = np.eye(4)
        pose[0, 3] = 0.5 * k + 0.1
        poses.append(pose)
    with open(path / "poses.txt", "w") as f:
        for pose in poses:
            f.write(" ".join(f"{v:.17g}" for v in pose[:3].ravel()) + "\n")
    return poses


def write_bag(seq, bag, *options):
    subprocess.run(["/usr/bin/python3", str(WRITER), str(seq), str(bag), *options], check=True)


def test_read_bag_yields_the_scans_and_poses_written(tmp_path):
    poses = kitti_folder(tmp_path / "seq")
    write_bag(tmp_path / "seq", tmp_path / "drive.bag", "--compression", "lz4")
    scans = list(strata.read_bag(tmp_path / "drive.bag"))
    assert len(scans) == 3
    for k, scan in enumerate(scans):
        cloud = np.fromfile(tmp_path / "seq" / "velodyne" / f"{k:06d}.bin", np.float32).reshape(-1, 4)
        np.testing.assert_array_equal(scan.points, cloud[:, :3].astype(np.float64))
        np.testing.assert_array_equal(scan.intensity, cloud[:, 3])
        np.testing.assert_allclose(scan.pose, poses[k], atol=1e-9)
        assert scan.time == pytest.approx(1317029540.0 + 0.1 * k)
    assert len(list(strata.read_bag(tmp_path / "drive.bag", frames="1:"))) == 2


def moving_bag(tmp_path):
    """The box's three scans recorded while driving 1 m along x during each 0.1 s sweep (each
    point's time in Velodyne's `time` field, /tf at 20 poses a sweep): deskewed, their rays
    start at ray origins of their own."""
    poses = kitti_folder(tmp_path / "seq")
    rng = np.random.default_rng(4)
    with open(tmp_path / "seq" / "times.txt", "w") as f:
        f.write("".join(f"{0.1 * k}\n" for k in range(len(poses))))
    with open(tmp_path / "end_poses.txt", "w") as f:
        for k, pose in enumerate(poses):
            rng.uniform(0, 0.1, 2000).astype(np.float32).tofile(
                tmp_path / "seq" / "velodyne" / f"{k:06d}.time")
            end = pose.copy()
            end[0, 3] += 1.0
            f.write(" ".join(f"{v:.17g}" for v in end[:3].ravel()) + "\n")
    write_bag(tmp_path / "seq", tmp_path / "drive.bag", "--point-time", "time", "--tf-rate",
              "20", "--motion", tmp_path / "end_poses.txt")
    return tmp_path / "drive.bag"


def test_a_session_integrates_a_bag_as_the_program_does(tmp_path):
    bag = moving_bag(tmp_path)
    run_strata("integrate", tmp_path / "cli.strata", "--voxel", 0.1, "--bag", bag)
    scans = list(strata.read_bag(bag))
    assert all(len(scan.ray_origins) > 2 and scan.ray_starts[0] == 0 for scan in scans)
    for name, rays in (("py.strata", True), ("one_origin.strata", False)):
        with strata.Map.create(tmp_path / name, voxel=0.1) as m:
            with m.session("drive") as s:
                for scan in scans:
                    s.integrate(scan) if rays else s.integrate(scan.points, scan.pose)
            assert [r["scans"] for r in m.sessions()] == [3]
    box = ([-4, -3, -2], [6, 3, 2])
    with strata.Map.open(tmp_path / "cli.strata", read_only=True) as cli:
        theirs = cli.voxels(*box)
    for name, same in (("py.strata", True), ("one_origin.strata", False)):
        with strata.Map.open(tmp_path / name, read_only=True) as m:
            ours = m.voxels(*box)
        identical = (np.array_equal(ours["ijk"], theirs["ijk"]) and
                     np.array_equal(ours["log_odds"], theirs["log_odds"]))
        assert identical == same, name


def test_read_bag_refusals_have_their_kinds(tmp_path):
    kitti_folder(tmp_path / "seq")
    write_bag(tmp_path / "seq", tmp_path / "two.bag", "--extra-cloud-topic")
    with pytest.raises(strata.InvalidArgumentError, match="--points-topic"):
        strata.read_bag(tmp_path / "two.bag")
    with pytest.raises(strata.NotFoundError, match="no topic /lidar"):
        strata.read_bag(tmp_path / "two.bag", points_topic="/lidar")
    with pytest.raises(strata.NotFoundError, match="missing.bag"):
        strata.read_bag(tmp_path / "missing.bag")
    (tmp_path / "not.bag").write_bytes(b"x" * 64)
    with pytest.raises(strata.FormatError, match="not.bag"):
        strata.read_bag(tmp_path / "not.bag")
