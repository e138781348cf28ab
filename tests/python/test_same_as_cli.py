"""The module and the program give the same results on the same scans: a map integrated from
numpy arrays is voxel-identical to `strata integrate` on the files they came from."""
import numpy as np
import pytest

import strata
from conftest import DATA_DIR, kitti_scans, run_strata, skip_without_data

EVERYWHERE = ([-1e4, -1e4, -1e4], [1e4, 1e4, 1e4])


def assert_same_voxels(a: strata.VoxelMap, b: strata.VoxelMap):
    va, vb = a.voxels(*EVERYWHERE), b.voxels(*EVERYWHERE)
    assert len(va["log_odds"]) > 10000
    for key in va:
        np.testing.assert_array_equal(va[key], vb[key], err_msg=key)


def integrate_from_numpy(path, sequence, frames=None, voxel=0.2):
    with strata.Map.create(path, voxel=voxel) as m:
        with m.session() as s:
            for points, pose, labels in kitti_scans(sequence, frames):
                s.integrate(points, pose, labels=labels)
        return m.snapshot()


def test_a_simulated_street_from_numpy_equals_strata_integrate(tmp_path, street_sequence):
    ours = integrate_from_numpy(tmp_path / "ours", street_sequence)
    run_strata("integrate", tmp_path / "theirs", "--kitti", street_sequence)
    with strata.Map.open(tmp_path / "theirs", read_only=True) as theirs:
        assert_same_voxels(ours, theirs.snapshot())
    assert ours.info()["labelled_voxels"] > 1000


def test_kitti_00_from_numpy_equals_strata_integrate(tmp_path):
    sequence = DATA_DIR / "kitti00"
    skip_without_data(sequence / "velodyne")
    ours = integrate_from_numpy(tmp_path / "ours", sequence, frames=range(2))
    run_strata("integrate", tmp_path / "theirs", "--kitti", sequence, "--frames", "0:2")
    with strata.Map.open(tmp_path / "theirs", read_only=True) as theirs:
        assert_same_voxels(ours, theirs.snapshot())


def test_map_info_equals_strata_info_json(tmp_path, street_sequence):
    import json
    run_strata("integrate", tmp_path / "map", "--kitti", street_sequence, "--name", "first")
    run_strata("integrate", tmp_path / "map", "--kitti", street_sequence, "--name", "second")
    for as_of in (None, "first"):
        args = ["info", tmp_path / "map", "--json"] + ([] if as_of is None else ["--as-of", as_of])
        cli = run_strata(*args).stdout
        expected = json.loads(cli[cli.index("{"):])
        with strata.Map.open(tmp_path / "map", read_only=True) as m:
            ours = m.info(as_of)
        # What the directory holds on disk changes while a reader has SQLite's files open.
        for d in (expected, ours):
            d.pop("disk_bytes")
            d["bytes"].pop("catalog")
        assert ours == expected
        assert ours["occupied_voxels"] > 1000
        assert len(ours["sessions"]) == (2 if as_of is None else 1)
    with strata.Map.open(tmp_path / "map", read_only=True) as m:
        with pytest.raises(strata.NotFoundError, match="no session"):
            m.info("third")
