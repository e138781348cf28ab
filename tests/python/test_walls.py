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
