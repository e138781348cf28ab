"""read_points, read_kitti and simulate: the io readers and the simulator, arrays out."""
import numpy as np
import pytest

import strata
from conftest import kitti_scans


def test_read_points_reads_text_with_labels(tmp_path):
    path = tmp_path / "cloud.txt"
    path.write_text("1 2 3 10\n4 5 6 40\n")  # SemanticKITTI 10 car, 40 road
    scan = strata.read_points(path)
    np.testing.assert_array_equal(scan.points, [[1, 2, 3], [4, 5, 6]])
    assert [strata.CLASSES[c] for c in scan.classes] == ["vehicle", "ground"]
    np.testing.assert_array_equal(scan.pose, np.eye(4))


def test_read_points_errors_have_their_kinds(tmp_path):
    with pytest.raises(strata.NotFoundError, match="missing.pcd"):
        strata.read_points(tmp_path / "missing.pcd")
    bad = tmp_path / "bad.txt"
    bad.write_text("1 2 3\n4 5\n")
    with pytest.raises(strata.Error, match="bad.txt"):
        strata.read_points(bad)
    bin_file = tmp_path / "odd.bin"
    bin_file.write_bytes(b"\0" * 7)
    with pytest.raises(strata.FormatError, match="odd.bin"):
        strata.read_points(bin_file)


def test_simulate_yields_what_strata_simulate_writes(street_sequence):
    from conftest import STREET
    ours = list(strata.simulate(STREET, max_scans=4))
    theirs = list(kitti_scans(street_sequence))
    assert len(ours) == len(theirs) == 4
    for scan, (points, pose, labels) in zip(ours, theirs):
        assert scan.points.dtype == np.float32 and len(scan.points) > 50000
        np.testing.assert_array_equal(scan.points, points)
        np.testing.assert_array_equal(scan.labels, labels)
        np.testing.assert_allclose(scan.pose, pose, atol=1e-6)  # poses.txt keeps ~9 digits
        assert scan.classes.max() < len(strata.CLASSES)


def test_simulate_refuses_a_missing_session_and_scene(tmp_path):
    with pytest.raises(strata.InvalidArgumentError, match="session 5 does not exist"):
        next(strata.simulate("demo", session=5))
    with pytest.raises(strata.Error, match="nope.json"):
        next(strata.simulate(tmp_path / "nope.json"))
