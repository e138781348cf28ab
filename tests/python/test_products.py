"""Map.walls(save=True) and Map.vehicles(save=True) store what `strata walls` and `strata
vehicles` store on the same map: the same commits, rows and map; bad input is refused before
anything is read or written."""
import json
import shutil
import sqlite3

import numpy as np
import pytest

import strata
from conftest import run_strata, tree_digest

EVERYWHERE = ([-1e4] * 3, [1e4] * 3)


def rows(path, kind):
    """Every row of the map's `kind` view (`SELECT * FROM walls`), read without writing."""
    with sqlite3.connect(f"file:{path}/catalog.sqlite?mode=ro", uri=True) as catalog:
        return catalog.execute(f"SELECT * FROM {kind} ORDER BY id").fetchall()


def without_times(report):
    report.pop("seconds", None)
    if "stats" in report:
        report["stats"] = {k: v for k, v in report["stats"].items() if "seconds" not in k}
    return report


def info(path):
    """`strata info --json` less what differs between two copies: the path and file sizes that
    depend on SQLite's files."""
    out = run_strata("info", path, "--json").stdout
    d = json.loads(out[out.index("{"):])
    for key in ("map", "disk_bytes"):
        d.pop(key)
    d["bytes"].pop("catalog")
    return d


@pytest.fixture
def two_copies(tmp_path, street_sequence):
    """The simulated street integrated by the program, twice: one copy for the program, one
    for the module."""
    run_strata("integrate", tmp_path / "theirs", "--kitti", street_sequence)
    shutil.copytree(tmp_path / "theirs", tmp_path / "ours")
    return tmp_path / "theirs", tmp_path / "ours"


def test_saved_walls_and_vehicles_equal_what_the_program_stores(two_copies):
    theirs, ours = two_copies
    walls_cli = without_times(json.loads(run_strata("walls", theirs, "--json").stdout))
    vehicles_cli = without_times(json.loads(run_strata("vehicles", theirs, "--json").stdout))
    with strata.Map.open(ours) as m:
        walls = m.walls(save=True)
        vehicles = m.vehicles(save=True)
        cleaned = vehicles.pop("map").voxels(*EVERYWHERE)
    with strata.Map.open(theirs, read_only=True) as m:
        expected = m.snapshot().voxels(*EVERYWHERE)
    assert vehicles.pop("commit") == walls.pop("commit") + 1  # one commit each
    walls.pop("voxels")
    assert without_times(walls) == walls_cli
    assert without_times(vehicles) == vehicles_cli
    assert len(walls["walls"]) >= 5 and len(vehicles["vehicles"]) >= 3
    for kind in ("walls", "vehicles"):
        assert rows(ours, kind) == rows(theirs, kind)
        assert len(rows(ours, kind)) == len((walls if kind == "walls" else vehicles)[kind])
    for key in expected:  # the cleaned map as stored: the program's, voxel for voxel
        np.testing.assert_array_equal(cleaned[key], expected[key], err_msg=key)
    assert info(ours) == info(theirs)  # the newest commit, voxels by class, bytes by kind
    assert sorted(p.name for p in (ours / "tiles").rglob("*.vdb")) == \
        sorted(p.name for p in (theirs / "tiles").rglob("*.vdb"))


def test_saving_is_refused_before_any_work_and_leaves_the_map(two_copies):
    _, path = two_copies
    before = tree_digest(path)
    with strata.Map.open(path, read_only=True) as m:
        with pytest.raises(strata.InvalidArgumentError, match="read-only.*store its walls"):
            m.walls(save=True)
        with pytest.raises(strata.InvalidArgumentError, match="read-only.*store its vehicles"):
            m.vehicles(save=True)
        assert "map" in m.vehicles() and "commit" not in m.walls()  # reading needs no writer
    with strata.Map.open(path) as m:
        first = m.sessions()[0]["name"]
        with pytest.raises(strata.InvalidArgumentError, match="as_of reads an older state"):
            m.walls(as_of=first, save=True)
        with pytest.raises(strata.InvalidArgumentError, match="as_of reads an older state"):
            m.vehicles(as_of=first, save=True)
        with pytest.raises(strata.InvalidArgumentError, match="unknown wall option 'windw_m'"):
            m.walls(save=True, windw_m=2.0)
        with pytest.raises(strata.InvalidArgumentError, match="source"):
            m.vehicles(save=True, source="radar")
    assert tree_digest(path) == before


def test_saved_static_map_equals_what_the_program_stores(two_copies):
    theirs, ours = two_copies
    cli = json.loads(run_strata("dynamic", theirs, "--json").stdout)
    with strata.Map.open(ours) as m:
        found = m.dynamic(save=True)
        static = found.pop("map").voxels(*EVERYWHERE)
        with pytest.raises(strata.InvalidArgumentError, match="margin_voxels"):
            m.dynamic(margin=-1)

    with strata.Map.open(theirs, read_only=True) as m:
        expected = m.snapshot().voxels(*EVERYWHERE)
    # The stored commit, after the session's that the program's report names.
    assert found.pop("commit") == cli.pop("commit") + 1
    cli.pop("map")  # the path; Python's "map" is the static map itself
    assert found == cli
    assert rows(ours, "dynamic") == rows(theirs, "dynamic")
    for key in expected:
        np.testing.assert_array_equal(static[key], expected[key], err_msg=key)


def test_dynamic_options_are_the_programs(tmp_path):
    """occupied_too, remove_scattered and min_object act as --occupied-too, --remove-scattered
    and --min-object do, on a box that moved over a ground plane (a sensor at rest)."""
    path = tmp_path / "map"
    grid = np.arange(-12.0, 12.0, 0.1)
    ground = np.array([[x, y, -1.6] for x in grid for y in np.arange(-4.0, 4.0, 0.1)])
    side = np.arange(0.0, 1.0, 0.1)
    box = np.array([[x, y, z] for x in side for y in side for z in side - 1.4])
    with strata.Map.create(path, voxel=0.2) as m:
        with m.session("drive") as s:
            for k in range(10):  # the box drives past at 2 m a scan
                s.integrate(np.vstack([ground, box + [2.0 * k - 9.0, 1.5, 0.0]]), np.eye(4))
    with strata.Map.open(path, read_only=True) as m:
        for options, flags in (({}, []), ({"occupied_too": True}, ["--occupied-too"]),
                               ({"min_object": 10**6}, ["--min-object", str(10**6)]),
                               ({"min_object": 10**6, "remove_scattered": True},
                                ["--min-object", str(10**6), "--remove-scattered"])):
            ours = m.dynamic(**options)
            ours.pop("map")
            theirs = json.loads(run_strata("dynamic", path, "--json", "--no-save",
                                           *flags).stdout)
            theirs.pop("map")
            assert ours == theirs, flags
            if not flags:
                assert ours["removed_voxels"] > 0  # the box's trail
                base = ours
            elif flags[0] == "--occupied-too":
                assert ours["removed_voxels"] > base["removed_voxels"]  # where it stopped
            elif "--remove-scattered" in flags:
                # every group removed: the trail and what the default kept as scattered
                assert ours["removed_voxels"] == base["removed_voxels"] + base["scattered_voxels"]
            else:
                assert ours["removed_voxels"] == 0  # every group is "scattered", kept


# A budget the street in 6.4 m tiles does not fit whole but each tile with its neighbours' layers
# does (measured when the test was written: 21.9 MB a tile for the moving things; the vehicles'
# tile with its halo of 9 tiles, 68.9 MB, is more than the whole map, which fits 70 MB).
TILED_BUDGET_MB = 50.0


def test_dynamic_and_vehicles_take_the_programs_memory_budget(tmp_path, street_sequence):
    """memory_budget_mb is the program's --memory-budget: under one the map does not fit,
    Map.dynamic judges it tile by tile with the program's report, rows and stored map, and "map"
    None (there is no whole static map to hand over); a budget below one tile is refused as the
    program refuses it, the map unchanged."""
    theirs, ours = tmp_path / "theirs", tmp_path / "ours"
    run_strata("integrate", theirs, "--kitti", street_sequence, "--tile-size", 6.4)
    shutil.copytree(theirs, ours)
    before = tree_digest(ours)
    with strata.Map.open(ours, read_only=True) as m:
        whole = m.dynamic(memory_budget_mb=0)
        assert whole.pop("map") is not None  # read whole: the static map
        tiled = m.dynamic(memory_budget_mb=TILED_BUDGET_MB)
        assert tiled.pop("map") is None
        assert tiled == whole  # (nothing moves in this street: the rows below are its objects)
        for analysis in (m.dynamic, m.vehicles):
            with pytest.raises(strata.RefusedError, match="memory-budget"):
                analysis(memory_budget_mb=1)
            with pytest.raises(strata.InvalidArgumentError, match="memory_budget_mb"):
                analysis(memory_budget_mb=-1)
        assert "walls" in m.walls(memory_budget_mb=1000)
    assert tree_digest(ours) == before
    cli = json.loads(run_strata("dynamic", theirs, "--json", "--memory-budget",
                                str(TILED_BUDGET_MB)).stdout)
    with strata.Map.open(ours) as m:
        found = m.dynamic(save=True, memory_budget_mb=TILED_BUDGET_MB)
    assert found.pop("map") is None
    cli.pop("map")  # the path
    assert found.pop("commit") == cli.pop("commit") + 1
    assert found == cli
    assert rows(ours, "dynamic") == rows(theirs, "dynamic")
    with strata.Map.open(ours, read_only=True) as a, strata.Map.open(theirs, read_only=True) as b:
        mine, expected = a.snapshot().voxels(*EVERYWHERE), b.snapshot().voxels(*EVERYWHERE)
    for key in expected:
        np.testing.assert_array_equal(mine[key], expected[key], err_msg=key)
