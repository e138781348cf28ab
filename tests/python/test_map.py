"""strata.Map: sessions commit at the end of a `with` block and leave nothing behind when it
raises; snapshots, locks and read-only maps behave as the store promises (docs/store.md)."""
import numpy as np
import pytest

import strata
from conftest import tree_digest


def integrate(session, scans):
    for scan in scans:
        session.integrate(scan.points, scan.pose, labels=scan.labels)


def test_a_session_commits_at_the_end_of_its_block(tmp_path, demo_scans):
    with strata.Map.create(tmp_path / "map", voxel=0.2) as m:
        assert m.sessions() == []
        with m.session("drive") as s:
            integrate(s, demo_scans)
            assert m.sessions() == []  # nothing visible before the commit
        assert s.record["name"] == "drive" and s.record["scans"] == 3
        assert s.record["points"] == sum(len(x.points) for x in demo_scans)
        assert [x["name"] for x in m.sessions()] == ["drive"]
        q = m.occupancy(demo_scans[0].points[:1000].astype(np.float64)
                        @ demo_scans[0].pose[:3, :3].T + demo_scans[0].pose[:3, 3])
        assert (q["state"] == 1).mean() > 0.9  # the endpoints of a scan are occupied


def test_a_session_that_raises_leaves_nothing_behind(tmp_path, demo_scans):
    path = tmp_path / "map"
    with strata.Map.create(path, voxel=0.2) as m:
        with m.session("first") as s:
            integrate(s, demo_scans[:1])
        before = tree_digest(path)
        with pytest.raises(KeyError):
            with m.session("second") as s:
                integrate(s, demo_scans[1:])
                raise KeyError("the user's own error")
        assert tree_digest(path) == before
        assert [x["name"] for x in m.sessions()] == ["first"]


def test_as_of_shows_the_map_right_after_a_session(tmp_path, demo_scans):
    with strata.Map.create(tmp_path / "map", voxel=0.2) as m:
        with m.session("one") as s:
            integrate(s, demo_scans[:1])
        with m.session("two") as s:
            integrate(s, demo_scans[1:])
        one, two = m.as_of("one"), m.as_of(2)
        assert 0 < one.info()["observed_voxels"] < two.info()["observed_voxels"]
        assert two.info() == m.snapshot().info()
        with pytest.raises(strata.NotFoundError, match="nosuch"):
            m.as_of("nosuch")
        with pytest.raises(strata.InvalidArgumentError, match="snapshot"):
            one.integrate(demo_scans[0].points, demo_scans[0].pose)


# Every format whose bytes depend only on the map (a .vdb file carries a random UUID of its own).
@pytest.mark.parametrize("fmt", ["ply", "pcd", "png", "bt", "ot"])
def test_export_of_a_stored_map_equals_the_program_export(tmp_path, demo_scans, fmt):
    from conftest import run_strata
    with strata.Map.create(tmp_path / "map", voxel=0.2) as m:
        with m.session() as s:
            integrate(s, demo_scans)
        assert m.export(tmp_path / f"ours.{fmt}") == fmt
    run_strata("export", tmp_path / "map", "--out", tmp_path / f"theirs.{fmt}")
    ours = (tmp_path / f"ours.{fmt}").read_bytes()
    assert len(ours) > 100
    assert ours == (tmp_path / f"theirs.{fmt}").read_bytes()


def read_pcd(path):
    """x y z intensity of a binary PCD file that strata wrote (float32 fields)."""
    data = path.read_bytes()
    end = data.index(b"DATA binary\n") + len(b"DATA binary\n")
    assert b"FIELDS x y z intensity" in data[:end]
    return np.frombuffer(data[end:], dtype=np.dtype("<f4")).reshape(-1, 4)


def test_export_of_a_clouds_points_keeps_those_in_occupied_voxels(tmp_path, demo_scans):
    """The dynamic-map benchmark's output format: the points of a given cloud whose voxel the
    map has occupied, as Map.occupancy answers for them, in the cloud's order."""
    scan = demo_scans[0]
    world = scan.points.astype(np.float64) @ scan.pose[:3, :3].T + scan.pose[:3, 3]
    cloud = np.vstack([world, world + [0.0, 0.0, 1000.0]])  # the copy lies outside the map
    ply = tmp_path / "cloud.ply"
    with open(ply, "w") as f:
        f.write("ply\nformat ascii 1.0\nelement vertex %d\nproperty double x\n"
                "property double y\nproperty double z\nproperty float intensity\n"
                "end_header\n" % len(cloud))
        for i, p in enumerate(cloud):
            f.write("%.17g %.17g %.17g %d\n" % (p[0], p[1], p[2], i))
    with strata.Map.create(tmp_path / "map", voxel=0.2) as m:
        with m.session() as s:
            integrate(s, demo_scans)
        assert m.export(tmp_path / "kept.pcd", points=ply) == "pcd"
        occupied = m.occupancy(cloud)["state"] == 1
        with pytest.raises(strata.InvalidArgumentError, match="written as pcd"):
            m.export(tmp_path / "kept.ply", points=ply)
    kept = read_pcd(tmp_path / "kept.pcd")
    assert 0.5 * len(world) < len(kept) < len(world)  # some endpoints ended free
    np.testing.assert_array_equal(kept[:, 3], np.flatnonzero(occupied).astype(np.float32))
    np.testing.assert_allclose(kept[:, :3], cloud[occupied], atol=1e-4)  # float32 at < 100 m


def test_open_errors_have_their_kinds(tmp_path, demo_scans):
    with pytest.raises(strata.NotFoundError, match="no map here"):
        strata.Map.open(tmp_path / "missing")
    path = tmp_path / "map"
    writer = strata.Map.create(path)
    with pytest.raises(strata.InvalidArgumentError, match="holds a map already"):
        strata.Map.create(path)
    with pytest.raises(strata.MapLockedError):
        strata.Map.open(path)
    reader = strata.Map.open(path, read_only=True)  # readers do not need the lock
    with pytest.raises(strata.InvalidArgumentError, match="read-only"):
        reader.session("x")
    writer.close()
    with pytest.raises(strata.InvalidArgumentError, match="closed"):
        writer.sessions()
    with strata.Map.open(path) as again:  # the lock went with close()
        with again.session("x") as s:
            integrate(s, demo_scans[:1])
    assert [x["name"] for x in reader.sessions()] == ["x"]


def test_a_committed_session_cannot_be_used_again(tmp_path, demo_scans):
    with strata.Map.create(tmp_path / "map") as m:
        with m.session() as s:
            integrate(s, demo_scans[:1])
        with pytest.raises(strata.InvalidArgumentError, match="committed or aborted"):
            integrate(s, demo_scans[1:2])


def test_an_integration_error_names_the_scan_and_leaves_the_map(tmp_path):
    # A 100 m hall at 1 cm voxels: far over the per-scan memory budget (as the program's test,
    # tests/tools/TestCli.cpp), refused by the writer `strata integrate` uses, naming the scan.
    rng = np.random.default_rng(5)
    directions = rng.uniform(-1.0, 1.0, (4000, 3))
    hall = directions * (np.array([50.0, 40.0, 5.0]) / np.abs(directions)).min(axis=1)[:, None]
    path = tmp_path / "fine"
    with strata.Map.create(path, voxel=0.01) as m:
        before = tree_digest(path)
        with pytest.raises(strata.RefusedError, match=r"^scan 0 \(numpy\): .*larger voxel size"):
            with m.session() as s:
                s.integrate(hall, np.eye(4))
        assert m.sessions() == []
    assert tree_digest(path) == before
