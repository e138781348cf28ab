"""Map.walls reports what `strata walls --json --no-save` prints on the same map, and the wall
voxels it hands back as arrays belong to the walls of the report."""
import json

import numpy as np
import pytest

import strata
from conftest import run_strata


def test_walls_equal_strata_walls_json(tmp_path, street_sequence):
    path = tmp_path / "street"
    run_strata("integrate", path, "--kitti", street_sequence)
    theirs = json.loads(run_strata("walls", path, "--json", "--no-save").stdout)
    with strata.Map.open(path, read_only=True) as m:
        ours = m.walls()
    voxels = ours.pop("voxels")
    for report in (ours, theirs):  # run times differ from run to run
        report["stats"] = {k: v for k, v in report["stats"].items() if "seconds" not in k}
    assert ours == theirs
    assert len(ours["walls"]) >= 5
    ids = {w["id"] for w in ours["walls"]}
    assert set(np.unique(voxels["wall_id"])) == ids
    inliers = {w["id"]: w["inliers"] for w in ours["walls"]}
    for wall_id, count in zip(*np.unique(voxels["wall_id"], return_counts=True)):
        assert count == inliers[wall_id]
    slants = {w["id"]: w["slant_deg"] for w in ours["walls"]}
    np.testing.assert_allclose(voxels["slant_deg"], [slants[i] for i in voxels["wall_id"]],
                               atol=1e-4)


def test_unknown_wall_options_are_refused_with_the_list():
    m = strata.VoxelMap(0.2)
    with pytest.raises(strata.InvalidArgumentError, match="unknown wall option 'windw_m'"):
        m.walls(windw_m=2.0)
    with pytest.raises(strata.InvalidArgumentError, match="wrong type"):
        m.walls(window_m="wide")


def test_vehicles_equal_strata_vehicles_json_and_leave_the_map_unchanged(tmp_path,
                                                                        street_sequence):
    from conftest import tree_digest
    path = tmp_path / "street"
    run_strata("integrate", path, "--kitti", street_sequence)
    theirs = json.loads(run_strata("vehicles", path, "--json", "--no-save").stdout)
    before = tree_digest(path)
    with strata.Map.open(path, read_only=True) as m:
        ours = m.vehicles()
        vehicle = strata.CLASSES.index("vehicle")
        labels_before = m.voxels([-1e4] * 3, [1e4] * 3, occupied_only=True)["label"]
    cleaned = ours.pop("map")
    ours.pop("seconds", None), theirs.pop("seconds", None)
    assert ours == theirs
    assert len(ours["vehicles"]) >= 3
    labels_after = cleaned.voxels([-1e4] * 3, [1e4] * 3, occupied_only=True)["label"]
    assert (labels_after == vehicle).sum() < (labels_before == vehicle).sum() / 2
    assert tree_digest(path) == before
