"""Map.diff between two sessions of datasets/scenes/street_two_sessions.json (12 scans each):
the container and the new car placed between the sessions are found where the scene put them,
and the report is the one `strata diff --json` prints."""
import json

import numpy as np
import pytest

import strata
from conftest import SOURCE_DIR, run_strata, tree_digest

SCENE = SOURCE_DIR / "datasets" / "scenes" / "street_two_sessions.json"
# Measured: the objects' centroids 1.36 m (container, seen from one side) and 1.17 m (new car)
# from the scene's footprint centres; bound at about 2.2x.
CENTROID_TOLERANCE_M = 3.0


@pytest.fixture(scope="module")
def two_sessions(tmp_path_factory):
    path = tmp_path_factory.mktemp("diff") / "map"
    with strata.Map.create(path, voxel=0.2) as m:
        for k, name in enumerate(["before", "after"]):
            with m.session(name) as s:
                for scan in strata.simulate(SCENE, session=k, max_scans=12):
                    s.integrate(scan.points, scan.pose, labels=scan.labels)
    return path


def near(obj, xy):
    return np.hypot(obj["centroid"][0] - xy[0], obj["centroid"][1] - xy[1]) < CENTROID_TOLERANCE_M


def test_diff_finds_the_container_and_the_new_car_where_the_scene_put_them(two_sessions):
    before = tree_digest(two_sessions)
    with strata.Map.open(two_sessions, read_only=True) as m:
        d = m.diff("before", "after")
    added = [o for o in d["objects"] if o["kind"] == "added"]
    assert any(o["class"] == "other" and near(o, (69.0, -3.9)) for o in added), added
    assert any(o["class"] == "vehicle" and near(o, (80.0, 3.9)) for o in added), added
    assert len(d["added"]) == d["added_voxels"] and len(d["removed"]) == d["removed_voxels"]
    assert d["added"].shape[1] == 3
    assert tree_digest(two_sessions) == before  # a query only reads


def test_diff_reports_what_strata_diff_json_prints(two_sessions):
    with strata.Map.open(two_sessions, read_only=True) as m:
        ours = m.diff("before", "after", class_name="vehicle", region=(50, -10, 90, 10))
    theirs = json.loads(run_strata("diff", two_sessions, "--from", "before", "--to", "after",
                                   "--class", "vehicle", "--region", "50,-10,90,10",
                                   "--json").stdout)
    del ours["added"], ours["removed"]
    assert ours == theirs
    assert len(ours["objects"]) >= 2


def test_diff_with_an_unknown_session_or_class_raises(two_sessions):
    with strata.Map.open(two_sessions, read_only=True) as m:
        with pytest.raises(strata.Error, match="nosuch"):
            m.diff("before", "nosuch")
        with pytest.raises(strata.Error, match="spaceship"):
            m.diff("before", "after", class_name="spaceship")
