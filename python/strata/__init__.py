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

__all__ = ["CLASSES", "Error", "FormatError", "InvalidArgumentError", "IoError", "Map",
           "MapLockedError", "NotFoundError", "RefusedError", "Scan", "Session", "VoxelMap",
           "read_bag", "read_kitti", "read_points", "simulate"]


@dataclass
class Scan:
    """One LiDAR sweep as arrays.

    points: (N, 3) sensor frame, metres; pose: (4, 4) sensor-to-map transform (None: a sweep
    read unposed, for a session with odometry=True to pose); labels: (N,) SemanticKITTI ids
    (class | instance << 16) or None; classes: (N,) strata class ids (index into strata.CLASSES)
    or None; intensity: (N,) or None; time: seconds; ray_origins (R, 3) and ray_starts (R,):
    where the rays of a deskewed sweep start (run r: points ray_starts[r] up to the next run's
    start, from ray_origins[r] in the sensor frame), or None when every ray starts at the sensor;
    times: (N,) seconds after `time` at which each point was measured (a sweep read unposed,
    not yet deskewed) or None.
    """
    points: np.ndarray
    pose: Optional[np.ndarray]
    labels: Optional[np.ndarray] = None
    classes: Optional[np.ndarray] = None
    intensity: Optional[np.ndarray] = None
    time: float = 0.0
    ray_origins: Optional[np.ndarray] = None
    ray_starts: Optional[np.ndarray] = None
    times: Optional[np.ndarray] = None


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


def read_bag(path, points_topic: Optional[str] = None, fixed_frame: Optional[str] = None,
             odom_topic: Optional[str] = None, deskew: bool = True,
             frames: Optional[str] = None, posed: bool = True) -> Iterator[Scan]:
    """Yields the sweeps of a robot recording, posed and deskewed, as `strata integrate --bag`
    reads them (docs/recordings.md): a ROS 1 .bag, an MCAP file, or a rosbag2 SQLite bag (a
    .db3 file or its folder).

    points_topic: the sensor_msgs/PointCloud2 topic (needed when there are several); fixed_frame:
    the frame of the poses (default: the tf tree's root); odom_topic: a nav_msgs/Odometry topic
    to pose the sweeps by instead of /tf; deskew: move each point by the pose of its own time
    where the clouds carry per-point times; frames: "A:B", the sweeps to read. Each Scan has
    float64 points in the sensor frame at the sweep's stamp, the pose there, intensity (or None),
    the stamp as `time` and, deskewed, the runs' ray origins. The recording is opened (and every
    refusal raised) at the call; the sweeps are read one at a time as the generator is iterated.
    To map them: `with m.session("drive") as s: for scan in strata.read_bag(p):
    s.integrate(scan)`.

    posed=False reads a recording without a trajectory as `strata odometry --bag` does: /tf and
    odom_topic are not read (only /tf_static, for the sensor's frame), each Scan comes with
    pose None and, where the clouds carry them, its points' `times` (deskew=False: without);
    a session made with odometry=True poses them, deskewing each sweep by the motion it finds:
    `with m.session("drive", odometry=True) as s: for scan in strata.read_bag(p, posed=False):
    s.integrate(scan)`. The recording's IMU is not used here (`strata odometry` predicts each
    sweep's rotation with its gyro).
    """
    rec = _strata._Recording(str(path), points_topic or "", fixed_frame or "", odom_topic or "",
                             deskew, frames or "", posed)

    def sweeps():
        for k in range(len(rec)):
            d = rec.scan(k)
            yield Scan(points=d["points"], pose=d["pose"] if posed else None,
                       intensity=d["intensity"], time=d["time"], ray_origins=d["ray_origins"],
                       ray_starts=d["ray_starts"], times=d["times"])
    return sweeps()


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


class Session:
    """One session being added to a Map: integrate scans, then commit them all at once.

    Used as `with map.session("name") as s: s.integrate(points, pose)`, it commits when the
    block ends and, when the block raises, removes what it wrote: the map is as before.
    """

    def __init__(self, map: "Map", name: str = "", memory_budget_mb: float = 0.0,
                 odometry: bool = False, start=None):
        self._map = map
        self._odometry = odometry
        self._impl = _strata._Session(map._impl, name, memory_budget_mb, odometry, start)

    def integrate(self, points, pose=None, labels=None, classes=None, ray_origins=None,
                  ray_starts=None, times=None, time: float = 0.0) -> dict:
        """Integrates one scan (see VoxelMap.integrate for the arrays, or give a strata.Scan
        alone) with the map's integration rule, through the same session writer as
        `strata integrate`; nothing reaches the map on disk before commit(). Returns
        {"points", "dropped", "clipped"}. An error about the scan names it
        ("scan 3 (numpy): ..."). In a session made with odometry=True give no pose: the
        odometry registers the points to the scans before (a Scan's pose is ignored), and a
        scan it cannot register raises RefusedError; a Scan with its points' `times` (read
        with strata.read_bag(..., posed=False)) is predicted over its `time` and deskewed by
        the motion found."""
        if isinstance(points, Scan):
            if pose is not None:
                raise TypeError("integrate(scan) takes the pose from the Scan")
            s = points
            # A Scan from strata.simulate has both; the labels (with instances) are the fuller.
            classes = s.classes if s.labels is None else None
            return self._impl.integrate(s.points, None if self._odometry else s.pose, s.labels,
                                        classes, s.ray_origins, s.ray_starts,
                                        s.times if self._odometry else None, s.time)
        return self._impl.integrate(points, pose, labels, classes, ray_origins, ray_starts,
                                    times, time)

    @property
    def poses(self) -> Optional[np.ndarray]:
        """With odometry=True, the poses the odometry found so far, (N, 4, 4) in the first scan's
        frame turned level by its ground plane, or in the map's frame for a session given a
        `start` (docs/odometry.md); None for a session given its poses."""
        return self._impl.poses

    @property
    def alignment(self) -> Optional[dict]:
        """For a session given a `start`, once its first scan is in: that scan's alignment to the
        map, as Map.register reports it (T, converged, rmse_m, overlap, ..., "pose"); else
        None."""
        return self._impl.alignment

    @property
    def gravity(self) -> Optional[dict]:
        """With odometry=True, where the map's up came from once a scan is in: {"source":
        "ground_plane" (the first scan's ground) or "first_scan" (none found: the first scan's
        z), "tilt_deg", "points", "rms_m", "height_m", "failure" (why no ground)}, or for a
        session given a `start` {"source": "map", "map_points": the map's points its odometry
        took in}; else None (docs/odometry.md, "Gravity")."""
        return self._impl.gravity

    def commit(self) -> dict:
        """Writes the session in one transaction; returns its record (as Map.sessions())."""
        record = self._impl.commit()
        self._map._newest = None
        return record

    def abort(self) -> None:
        """Drops everything this session wrote; the map on disk stays as it was."""
        self._impl.abort()

    @property
    def record(self) -> Optional[dict]:
        """The committed session's record, None before commit."""
        return self._impl.record

    def __enter__(self) -> "Session":
        return self

    def __exit__(self, exc_type, exc, tb) -> bool:
        if exc_type is None:
            self.commit()
        else:
            self.abort()
        return False


class Map:
    """A map on disk: a transactional store of sessions (docs/store.md).

    Create one with Map.create, open one with Map.open; add scans in sessions; query the newest
    state (occupancy, voxels, columns) or any session's (as_of); export for viewers. A Map
    opened for writing holds the map's writer lock until close() (or the end of a `with`).
    """

    def __init__(self, impl):
        self._impl = impl
        self._newest = None

    @staticmethod
    def create(path, voxel: float = 0.2, tile_size: float = 64.0, origin=None,
               max_range: float = 50.0, min_range: float = 0.0, points_only: bool = False,
               keep_point_means: bool = True) -> "Map":
        """Creates an empty map in `path` (absent or empty) and opens it for writing.

        voxel and tile_size in metres; origin: the world position of map coordinate (0, 0, 0)
        for georeferenced data; the integration rule as `strata integrate`'s options."""
        return Map(_strata._Map.create(str(path), voxel, tile_size, origin, max_range,
                                       min_range, points_only, keep_point_means))

    @staticmethod
    def open(path, read_only: bool = False) -> "Map":
        """Opens the map in `path`; for writing (the default) it takes the writer lock
        (MapLockedError when another process holds it)."""
        return Map(_strata._Map.open(str(path), read_only))

    def close(self) -> None:
        """Releases the map (and its writer lock)."""
        self._impl.close()
        self._newest = None

    def __enter__(self) -> "Map":
        return self

    def __exit__(self, exc_type, exc, tb) -> bool:
        self.close()
        return False

    @property
    def path(self) -> str:
        return self._impl.path

    @property
    def voxel_size(self) -> float:
        return self._impl.voxel_size

    def session(self, name: str = "", memory_budget_mb: float = 0.0,
                odometry: bool = False, start=None) -> Session:
        """A new session named `name` (default session_<id>); use it in a `with` block.
        memory_budget_mb > 0 keeps at most that many MB of tiles in memory. odometry=True: the
        scans come without poses and LiDAR odometry estimates them (docs/odometry.md); with
        `start` (a guess of the first scan's pose in the map: a 4x4 pose or (x, y, z, yaw_deg))
        the session starts in the map as `strata integrate --odometry --align --init` does: its
        first scan is aligned to the map (RefusedError when it does not fit) and the odometry
        runs in the map's frame, on the map's points."""
        return Session(self, name, memory_budget_mb, odometry, start)

    def sessions(self) -> list:
        """The map's sessions, oldest first, as dicts (id, name, scans, points, ...)."""
        return self._impl.sessions()

    def info(self, as_of=None) -> dict:
        """What the map holds, with the keys of `strata info --json`: voxel_size_m, origin,
        occupied_voxels, free_voxels, classes, extent_min/max, tiles, bytes by kind
        (fused_current, fused_older, layers, products, catalog), disk_bytes, memory_bytes,
        sessions, ...; of the newest commit, or right after session `as_of` (id or name)."""
        return self._impl.info("" if as_of is None else str(as_of))

    def as_of(self, session) -> VoxelMap:
        """The map right after `session` (an id or a name) was committed, read-only."""
        return self._impl.load(str(session))

    def snapshot(self) -> VoxelMap:
        """The newest state as a read-only VoxelMap (read once, until the next commit)."""
        if self._newest is None:
            self._newest = self._impl.load("")
        return self._newest

    def occupancy(self, points) -> dict:
        """VoxelMap.occupancy on the newest state."""
        return self.snapshot().occupancy(points)

    def voxels(self, lo, hi, occupied_only: bool = False) -> dict:
        """VoxelMap.voxels on the newest state."""
        return self.snapshot().voxels(lo, hi, occupied_only)

    def columns(self, window: int = 0) -> dict:
        """VoxelMap.columns on the newest state."""
        return self.snapshot().columns(window)

    def walls(self, as_of=None, save: bool = False, memory_budget_mb: float = 512.0,
              **options) -> dict:
        """Walls and their slant angles (docs/walls.md) of the newest state (or as of a
        session), as `strata walls --json` reports them (walls, stats, config, ...), plus
        "voxels": the centre, slant_deg and wall_id of every wall voxel as arrays. Options are
        WallConfig's fields (window_m=1.5, level_to_ground=True, ...). memory_budget_mb: as
        the program's --memory-budget (0: no limit), a map that does not fit is read a group of
        tiles at a time, with the same walls.

        save=True stores them in the map as `strata walls` does (one commit: the slant_deg and
        wall_id grids and the walls table, `SELECT * FROM walls`) and adds "commit"; it needs
        the map open for writing and no as_of. Bad options are refused before anything is
        read or written."""
        return self._impl.walls("" if as_of is None else str(as_of), memory_budget_mb, save,
                                **options)

    def vehicles(self, as_of=None, source: str = "auto", ray_check: bool = True,
                 refill: bool = True, save: bool = False,
                 memory_budget_mb: float = 512.0) -> dict:
        """Parked vehicles cleared and the ground under them refilled (docs/vehicles.md), as
        `strata vehicles --json` reports them: vehicles [{id, center, size, yaw_deg, source,
        cleared_voxels, refilled_cells, refused_cells}], ... plus "map": the cleaned map as a
        read-only VoxelMap. source: "auto", "label" or "geometric".

        save=False (the default) leaves the map on disk unchanged. save=True stores the result
        as `strata vehicles` does (one commit: the cleaned map, the vehicle_cleared and
        vehicle_refilled grids and the vehicles table; as_of the previous session still shows
        the map as it was) and adds "commit"; "map" is then the map as stored. It needs the map
        open for writing and no as_of.

        memory_budget_mb: as the program's --memory-budget (0: no limit), a map that does not
        fit is read tile by tile, with the same vehicles; "map" is then None (save=True still
        stores the cleaned map, tile by tile)."""
        report = self._impl.vehicles("" if as_of is None else str(as_of), source, ray_check,
                                     refill, memory_budget_mb, save)
        return self._stored(report, save)

    def _stored(self, report: dict, save: bool) -> dict:
        """An edited map's report after save=True: the map as stored, read again (unless the
        analysis read it tile by tile: "map" None)."""
        if save:
            self._newest = None
            if "map" not in report:
                report["map"] = self.snapshot()
        return report

    def dynamic(self, as_of=None, session=None, margin: int = 1, faces: bool = False,
                min_object: int = 8, occupied_too: bool = False, remove_scattered: bool = False,
                save: bool = False, memory_budget_mb: float = 512.0) -> dict:
        """What moved taken out of the map (docs/dynamic.md), as `strata dynamic --json`
        reports it: objects [{object_id, voxels, min_x, ..., max_z, sessions}], removed_voxels,
        restored_voxels, static_voxels, ... plus "map": the static map as a read-only VoxelMap.
        session: only what that session (id or name) saw move. margin, faces, min_object,
        occupied_too and remove_scattered are the program's --margin, --faces, --min-object,
        --occupied-too and --remove-scattered.

        save=False (the default) leaves the map on disk unchanged. save=True stores the result
        as `strata dynamic` does (one commit: the static map, the dynamic_removed and
        dynamic_restored grids and the dynamic table; as_of the last session still shows the
        map as it was) and adds "commit"; "map" is then the map as stored. It needs the map open
        for writing and no as_of.

        memory_budget_mb: as the program's --memory-budget (0: no limit), a map whose tiles and
        session layers do not fit is judged a tile at a time with its neighbours' layers, with
        the same result (docs/dynamic.md, "Tile by tile"); "map" is then None (save=True still
        stores the static map, tile by tile)."""
        report = self._impl.dynamic("" if as_of is None else str(as_of),
                                    "" if session is None else str(session), margin, faces,
                                    min_object, occupied_too, remove_scattered, memory_budget_mb,
                                    save)
        return self._stored(report, save)

    def diff(self, a="map", b="map", region=None, class_name: str = "", min_voxels: int = 8,
             gap: int = 1, tolerance: int = 2, margin: int = 1, grow: int = 2,
             support: int = 3) -> dict:
        """What changed from side `a` to side `b`, as `strata diff --json` reports it
        (docs/change.md): objects [{id, kind, voxels, volume_m3, bbox_min, bbox_max, centroid,
        class, oriented_box}], added_voxels, removed_voxels, unknown_voxels, ... plus "added"
        and "removed": the centres of the changed voxels as (M, 3) arrays.

        A side is a session (id or name: what it saw), "map" (the newest map) or "map@SESSION"
        (the map right after it). region: (x0, y0, x1, y1), a polygon (x0, y0, x1, y1, x2, y2,
        ...) or that text; class_name: only objects of that class ("vehicle"); the thresholds
        as `strata diff`'s options. The map is only read."""
        return self._impl.diff(str(a), str(b), region, class_name, min_voxels, gap, tolerance,
                               margin, grow, support)

    def register(self, points, init=None, as_of=None, margin: float = 10.0,
                 min_range: float = 3.0, max_range: float = 60.0, min_overlap: float = 0.5,
                 max_rmse: float = 0.15) -> dict:
        """Where one scan (points (N, 3) in its sensor frame) sits in the map, as
        `strata register --json` reports it (docs/registration.md): T (16 numbers, row-major,
        scan -> map), converged, rmse_m, overlap, refusal, xyz_m, yaw_deg, ... plus "pose" as a
        (4, 4) array. init: the guess, a 4x4 pose or (x, y, z, yaw_deg); margin: metres of map
        read around it; points outside [min_range, max_range] of the sensor are left out. A
        registration refused on its merits (overlap below min_overlap, rmse above max_rmse)
        comes back with converged False and the reason in "refusal"; RefusedError when the map
        has no surface near the guess. The map is only read."""
        return self._impl.register(points, init, "" if as_of is None else str(as_of), margin,
                                   min_range, max_range, min_overlap, max_rmse)

    def localize(self, points, floor: int, init=None, l1: float = -0.2, l2: float = 3.1,
                 min_range: float = 0.5, max_range: float = 60.0, min_overlap=None,
                 max_rmse=None) -> dict:
        """Where one scan (points (N, 3) in its sensor frame) sits in storey `floor` of a
        stacked map (`strata stack` records the storeys; docs/registration.md), registered to
        the slice l1 < z - z_floor < l2 of the map only, as `strata localize --json` reports it:
        T (16 numbers, row-major, scan -> map), converged, rmse_m, overlap, refusal, xyz_m,
        yaw_deg, iterations, map_points, floor, z_m, ... plus "pose" as a (4, 4) array.

        init: the guess in the map frame, a 4x4 pose or (x, y, z, yaw_deg) (default: the
        storey's frame). Points outside [min_range, max_range] of the sensor are left out;
        min_overlap and max_rmse default to the program's. A registration refused on its merits
        comes back with converged False and the reason in "refusal"; InvalidArgumentError for a
        storey that is not recorded, RefusedError when its slice holds no surface. The map is
        only read."""
        if isinstance(floor, bool) or not isinstance(floor, (int, np.integer)):
            raise InvalidArgumentError(f"floor must be a storey index (an int); got {floor!r}")
        return self._impl.localize(points, int(floor), init, l1, l2, min_range, max_range,
                                   min_overlap, max_rmse)

    def export(self, path, format: str = "", as_of=None, points=None) -> str:
        """Writes the map (or its state as of a session) as vdb, bt, ot, ply, pcd or png
        (default: from the file name); returns the format written. With `points` (a point
        cloud file), a pcd of that cloud's points whose voxel the map has occupied (the
        dynamic-map benchmark's format, docs/dynamic.md)."""
        return self._impl.export(str(path), format, "" if as_of is None else str(as_of),
                                 "" if points is None else str(points))
