"""LiDAR sweeps as point-cloud files other tools read: PCD (PCL, CloudCompare, Open3D) and KITTI .bin.

Written on request (``raysim render --formats pcd,kitti``) from ``lidar/sweeps/*.npz``, one file per
revolution, points in the sensor frame (x forward, y left, z up, m):

- ``lidar/pcd/NNNNNN.pcd``: PCD v0.7, binary, fields ``x y z intensity ring time`` (float32 x 4,
  uint16, float32; ``time`` in s since the sweep's first point), ``VIEWPOINT 0 0 0 1 0 0 0``;
- ``lidar/kitti/NNNNNN.bin``: the KITTI Velodyne layout, float32 ``x y z reflectance`` per point,
  reflectance = intensity / 255.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from raysim.recording.npz import read_npz
from raysim.recording.staging import atomic_path

__all__ = ["FORMATS", "PCD_DTYPE", "velodyne_points", "pcd_bytes", "kitti_bytes", "write_point_cloud_files"]

FORMATS = ("pcd", "kitti")

PCD_DTYPE = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("intensity", "<f4"), ("ring", "<u2"), ("time", "<f4")])


def velodyne_points(sweep) -> np.ndarray:
    """(N,) packed points of one sweep (the NPZ arrays) in the velodyne driver's XYZIRT layout.

    Fields x, y, z, intensity (float32), ring (uint16), time (float32, s since the sweep's first
    point): 22 bytes a point, as ROS PointCloud2 (/lidar/points) and the PCD files carry them.
    """
    n = sweep["x"].size
    points = np.empty(n, dtype=PCD_DTYPE)
    points["x"], points["y"], points["z"] = sweep["x"], sweep["y"], sweep["z"]
    points["intensity"] = sweep["intensity"].astype(np.float32)
    points["ring"] = sweep["ring"].astype(np.uint16)
    t = np.asarray(sweep["time"], dtype=np.float64)
    points["time"] = (t - t.min()).astype(np.float32) if n else t.astype(np.float32)
    return points


def pcd_bytes(sweep) -> bytes:
    """Binary PCD v0.7 of one sweep (the NPZ arrays)."""
    points = velodyne_points(sweep)
    n = points.size
    header = (
        "# .PCD v0.7 - Point Cloud Data file format (raysim)\n"
        "VERSION 0.7\nFIELDS x y z intensity ring time\nSIZE 4 4 4 4 2 4\nTYPE F F F F U F\nCOUNT 1 1 1 1 1 1\n"
        f"WIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA binary\n"
    )
    return header.encode("ascii") + points.tobytes()


def kitti_bytes(sweep) -> bytes:
    """KITTI Velodyne .bin of one sweep: float32 (x, y, z, reflectance 0..1) per point."""
    points = np.stack([sweep["x"], sweep["y"], sweep["z"], sweep["intensity"].astype(np.float32) / 255.0], axis=1)
    return points.astype("<f4").tobytes()


def write_point_cloud_files(recording: Path, formats: tuple[str, ...]) -> dict:
    """Write the requested formats for every sweep of ``recording``; returns file counts per format."""
    writers = {"pcd": (pcd_bytes, "pcd"), "kitti": (kitti_bytes, "bin")}
    sweeps = sorted((Path(recording) / "lidar" / "sweeps").glob("*.npz"))
    counts = {}
    for name in formats:
        to_bytes, ext = writers[name]
        folder = Path(recording) / "lidar" / name
        folder.mkdir(parents=True, exist_ok=True)
        for path in sweeps:  # one file per revolution, one at a time (memory flat)
            data = to_bytes(read_npz(path))
            with atomic_path(folder / f"{path.stem}.{ext}") as tmp:
                tmp.write_bytes(data)
        counts[f"lidar/{name}"] = len(sweeps)
    return counts
