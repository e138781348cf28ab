"""strata: a GPU-free voxel database for LiDAR maps, numpy in and out.

Scans go in as numpy arrays (points (N, 3), a 4x4 pose, optional labels), maps come back as
numpy arrays (occupancy at points, the voxels in a box, column statistics) and as the files
viewers open. Every call releases the GIL while C++ works. Errors are strata.Error and its
subclasses, one per kind the library reports. See docs/python.md.
"""
from dataclasses import dataclass
from typing import Iterator, Optional

import numpy as np

from . import _strata
from ._strata import (CLASSES, Error, FormatError, InvalidArgumentError, IoError,
                      MapLockedError, NotFoundError, RefusedError, VoxelMap)

__all__ = ["CLASSES", "Error", "FormatError", "InvalidArgumentError", "IoError",
           "MapLockedError", "NotFoundError", "RefusedError", "Scan", "VoxelMap",
           "read_kitti", "read_points", "simulate"]


@dataclass
class Scan:
    """One LiDAR sweep as arrays.

    points: (N, 3) sensor frame, metres; pose: (4, 4) sensor-to-map transform;
    labels: (N,) SemanticKITTI ids (class | instance << 16) or None;
    classes: (N,) strata class ids (index into strata.CLASSES) or None;
    intensity: (N,) or None; time: seconds.
    """
    points: np.ndarray
    pose: np.ndarray
    labels: Optional[np.ndarray] = None
    classes: Optional[np.ndarray] = None
    intensity: Optional[np.ndarray] = None
    time: float = 0.0


def read_points(path, bin_fields: int = 0, origin=None) -> Scan:
    """Reads a point cloud: .pcd, .ply, .las, raw float32 .bin (KITTI, nuScenes .pcd.bin),
    text (.txt .xyz .csv .dat) and .bz2-compressed text.

    Points are float64 in the file's frame minus `origin`; `classes` holds the file's labels
    mapped to strata's classes (None when it has none). bin_fields: float32 values per point of
    a .bin file (4 KITTI, 5 nuScenes, 0 from the name or size). The pose is the identity.
    """
    d = _strata._read_points(str(path), bin_fields, origin)
    return Scan(points=d["points"], pose=d["pose"], classes=d["classes"],
                intensity=d["intensity"], time=d["time"])


def read_kitti(sequence) -> dict:
    """Indexes a KITTI / SemanticKITTI sequence folder without loading scans.

    Returns {"scans": [velodyne/*.bin paths], "labels": [labels/*.label paths or empty],
    "poses": (N, 4, 4) sensor poses (calib.txt's Tr applied, as `strata integrate --kitti`),
    "times": (N,)}. Read a scan with np.fromfile(path, np.float32).reshape(-1, 4)[:, :3].
    """
    return _strata._read_kitti(str(sequence))


def simulate(scene="demo", session: int = 0, sensor: Optional[str] = None,
             seed: Optional[int] = None, max_scans: int = 0) -> Iterator[Scan]:
    """Yields the scans of one session of a simulated scene (docs/simulator.md), one at a time.

    scene: a scene file (datasets/scenes/*.json) or "demo" (a small built-in street).
    Each Scan carries float32 points in the sensor frame, SemanticKITTI `labels`, strata
    `classes` and the pose in the session's frame: what `strata simulate` writes for it.
    """
    sim = _strata._Simulation(str(scene), session, sensor or "", seed, max_scans)
    for k in range(len(sim)):
        d = sim.scan(k)
        yield Scan(points=d["points"], pose=d["pose"], labels=d["labels"],
                   classes=d["classes"], time=d["time"])
