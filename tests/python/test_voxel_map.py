"""Integration and queries of a map in memory, on geometry with a known answer: a flat wall
10 m ahead of a sensor at the origin, 4 m wide and 3 m tall."""
import numpy as np
import pytest

import strata
from conftest import wall_scan

VOXEL = 0.2


@pytest.fixture(scope="module")
def wall_map():
    m = strata.VoxelMap(VOXEL)
    counts = m.integrate(wall_scan(), np.eye(4), classes=np.full(len(wall_scan()), 2, np.uint8))
    assert counts == {"points": len(wall_scan()), "dropped": 0, "clipped": 0}
    return m


def test_occupancy_is_occupied_on_the_wall_free_before_it_unknown_behind(wall_map):
    probes = np.array([[10.05, 0.0, 0.5], [5.0, 0.0, 0.5], [12.0, 0.0, 0.5], [5.0, 8.0, 0.5]])
    q = wall_map.occupancy(probes)
    np.testing.assert_array_equal(q["state"], [1, 0, -1, -1])
    assert q["log_odds"][0] == pytest.approx(0.847, abs=1e-3)  # one hit: log(0.7 / 0.3)
    assert q["log_odds"][1] == pytest.approx(-0.405, abs=1e-3)  # one miss: log(0.4 / 0.6)
    assert np.isnan(q["log_odds"][2])
    assert q["label"][0] == strata.CLASSES.index("building")
    assert q["hits"][0] > 0


def test_voxels_in_a_box_around_the_wall_are_exactly_its_voxels(wall_map):
    v = wall_map.voxels([9.5, -3, -2], [10.5, 3, 3], occupied_only=True)
    # 4 m / 0.2 m = 20 columns across, 3 m / 0.2 m = 15 rows up, one voxel deep.
    assert len(v["log_odds"]) == 20 * 15
    assert set(v["ijk"][:, 0]) == {50}
    np.testing.assert_allclose(v["center"][:, 0], 10.1)
    assert (v["label"] == strata.CLASSES.index("building")).all()
    assert v["hits"].sum() == len(wall_scan())
    every = wall_map.voxels([-1, -3, -2], [10.5, 3, 3])
    assert len(every["log_odds"]) > 20 * 15  # free voxels in front of the wall too
    assert (every["log_odds"] < 0).sum() == len(every["log_odds"]) - 20 * 15


def test_columns_of_the_wall_give_its_height_and_point_counts(wall_map):
    c = wall_map.columns()
    occupied = c["voxels"] > 0
    assert occupied.sum() == 20  # one column per wall voxel across
    np.testing.assert_allclose(c["extent"][occupied], 3.0, atol=1e-5)
    np.testing.assert_allclose(c["z_min"][occupied], -1.0, atol=1e-5)
    assert c["points"].sum() == len(wall_scan())
    building = strata.CLASSES.index("building")
    assert (c["classes"][occupied][:, building] == 15).all()
    assert np.isnan(c["z_min"][~occupied]).all()
    window = wall_map.columns(window=1)
    assert window["points"].max() > c["points"].max()


def test_bad_queries_raise_invalid_argument(wall_map):
    with pytest.raises(strata.InvalidArgumentError, match="lo must not exceed hi"):
        wall_map.voxels([1, 0, 0], [0, 1, 1])
    with pytest.raises(strata.InvalidArgumentError, match="three numbers"):
        wall_map.voxels([0, 0], [1, 1, 1])
    with pytest.raises(strata.InvalidArgumentError, match="window must be >= 0"):
        wall_map.columns(window=-1)
    with pytest.raises(strata.InvalidArgumentError, match=r"shape \(N, 3\)"):
        wall_map.occupancy(np.zeros((2, 4)))


def test_export_writes_each_format_and_refuses_an_unknown_one(wall_map, tmp_path):
    for name in ["m.vdb", "m.bt", "m.ot", "m.ply", "m.png"]:
        assert wall_map.export(tmp_path / name) == name.split(".")[1]
        assert (tmp_path / name).stat().st_size > 100
    with pytest.raises(strata.InvalidArgumentError, match="unknown export format 'xyz'"):
        wall_map.export(tmp_path / "m.xyz")
    with pytest.raises(strata.InvalidArgumentError, match="OctoMap files must end in .bt"):
        wall_map.export(tmp_path / "m.vdb", format="bt")
    assert not (tmp_path / "m.xyz").exists()


def test_returned_arrays_own_their_data(wall_map):
    v = wall_map.voxels([9.5, -3, -2], [10.5, 3, 3])
    assert v["center"].flags["C_CONTIGUOUS"] and v["center"].flags["OWNDATA"] is False
    assert v["center"].base is not None  # the capsule holding the C++ vector
    del wall_map  # the arrays stay valid without the map
    assert np.isfinite(v["center"]).all()
