"""Map.register: a scan of the map found back from a guess 0.6 m and 4 degrees off, as
`strata register --json` reports it; the map is only read."""
import numpy as np
import pytest

import strata
from conftest import tree_digest

# Measured: 0.0051 m and 0.0052 deg off on the demo street (2026-12-02); bounds at 3x.
TRANSLATION_TOLERANCE_M = 0.015
YAW_TOLERANCE_DEG = 0.015


def yaw_deg(T):
    return np.degrees(np.arctan2(T[1, 0], T[0, 0]))


@pytest.fixture(scope="module")
def street_map(tmp_path_factory, demo_scans):
    path = tmp_path_factory.mktemp("register") / "map"
    with strata.Map.create(path, voxel=0.2) as m:
        with m.session("drive") as s:
            for scan in demo_scans:
                s.integrate(scan.points, scan.pose, labels=scan.labels)
    return path


def test_register_finds_a_scan_from_a_guess_off_by_0_6_m_and_4_degrees(street_map, demo_scans):
    scan = demo_scans[1]
    truth = scan.pose
    x, y, z = truth[:3, 3] + [0.5, -0.3, 0.1]
    before = tree_digest(street_map)
    with strata.Map.open(street_map, read_only=True) as m:
        r = m.register(scan.points, init=(x, y, z, yaw_deg(truth) + 4.0))
    assert r["converged"], r["refusal"]
    assert set(r) >= {"T", "converged", "rmse_m", "overlap", "refusal", "xyz_m", "yaw_deg",
                      "iterations", "map_points"}
    np.testing.assert_allclose(np.array(r["T"]).reshape(4, 4), r["pose"])
    assert np.linalg.norm(r["pose"][:3, 3] - truth[:3, 3]) < TRANSLATION_TOLERANCE_M
    assert abs(r["yaw_deg"] - yaw_deg(truth)) < YAW_TOLERANCE_DEG
    assert r["overlap"] > 0.5
    assert tree_digest(street_map) == before


def test_register_far_from_the_map_is_refused(street_map, demo_scans):
    with strata.Map.open(street_map, read_only=True) as m:
        with pytest.raises(strata.RefusedError, match="no surface near the guess"):
            m.register(demo_scans[0].points, init=(500.0, 500.0, 0.0, 0.0))
        with pytest.raises(strata.InvalidArgumentError, match="init must have shape"):
            m.register(demo_scans[0].points, init="north")
