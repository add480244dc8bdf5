"""Bag streams of the sensors: the mounts, LiDAR clouds, radar sectors and pictures, AIS sentences.

Each stream is a generator of :class:`~raysim.recording.rosbag.msgs.BagMessage` in time order,
reading one file (one revolution) at a time, so memory stays flat.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Callable, Iterator

import numpy as np

from groundfloor.frames import mount_transform
from groundfloor.recording import AIS_NMEA, LIDAR_SWEEPS, RADAR_SWEEPS
from raysim.recording.npz import read_npz
from raysim.recording.pointclouds import PCD_DTYPE, velodyne_points
from raysim.recording.rosbag.msgs import (BagMessage, duration, header, make, message_class, point, quaternion,
                                          quaternion_from_matrix)

__all__ = ["static_transforms", "lidar_clouds", "radar_sectors", "ais_sentences", "POINT_STEP"]

POINT_STEP = PCD_DTYPE.itemsize  # velodyne_pointcloud XYZIRT: 4 x float32, uint16 ring, float32 time: 22
#: PointField datatypes (sensor_msgs/PointField): FLOAT32 = 7, UINT16 = 4.
_CLOUD_FIELDS = (("x", 0, 7), ("y", 4, 7), ("z", 8, 7), ("intensity", 12, 7), ("ring", 16, 4), ("time", 18, 7))

NsOf = Callable[[float], int]


def _transform(t_ns: int, parent: str, child: str, rot: np.ndarray, trans) -> object:
    return make("geometry_msgs/msg/TransformStamped", header=header(t_ns, parent), child_frame_id=child,
                transform=make("geometry_msgs/msg/Transform",
                               translation=point(*trans, msgtype="geometry_msgs/msg/Vector3"),
                               rotation=quaternion(quaternion_from_matrix(rot))))


def static_transforms(scenario, t0_ns: int) -> Iterator[BagMessage]:
    """``/tf_static``: base_link -> lidar, radar (the mounts) and ais (the VHF antenna above the sea)."""
    transforms = []
    for frame, sensor in (("lidar", scenario.sensors.lidar), ("radar", scenario.sensors.radar)):
        rot, trans = mount_transform(sensor.mount)
        transforms.append(_transform(t0_ns, "base_link", frame, rot, trans))
    transforms.append(_transform(t0_ns, "base_link", "ais", np.eye(3), (0.0, 0.0, scenario.sensors.ais.antenna_height_m)))
    yield BagMessage(t0_ns, "/tf_static", "tf2_msgs/msg/TFMessage", make("tf2_msgs/msg/TFMessage", transforms=transforms))


def lidar_clouds(recording: Path, ns_of: NsOf) -> Iterator[BagMessage]:
    """``/lidar/points``: one PointCloud2 per revolution in the velodyne driver's layout, frame ``lidar``."""
    fields = [make("sensor_msgs/msg/PointField", name=n, offset=o, datatype=d, count=1) for n, o, d in _CLOUD_FIELDS]
    for path in sorted((recording / LIDAR_SWEEPS).glob("*.npz")):
        sweep = read_npz(path)
        points = velodyne_points(sweep)
        n = points.size
        t_ns = ns_of(float(sweep["time"].min()) if n else 0.0)
        msg = make("sensor_msgs/msg/PointCloud2", header=header(t_ns, "lidar"), height=1, width=n, fields=fields,
                   is_bigendian=False, point_step=POINT_STEP, row_step=POINT_STEP * n, data=points.view(np.uint8),
                   is_dense=True)
        yield BagMessage(t_ns, "/lidar/points", "sensor_msgs/msg/PointCloud2", msg)


def radar_sectors(recording: Path, ns_of: NsOf) -> Iterator[BagMessage]:
    """``/radar/sector`` (RadarSector) and ``/radar/image/compressed`` (the revolution's PPI, PNG).

    Both stamped at spoke 0 of the revolution; the picture is ``radar/ppi/NNNNNN.png`` as written.
    """
    ppi_dir = recording / "radar" / "ppi"
    radar_echo = message_class("marine_sensor_msgs/msg/RadarEcho")  # its one field given: built directly, 2048 a sweep
    for path in sorted((recording / RADAR_SWEEPS).glob("*.npz")):
        sweep = read_npz(path)
        echo, az, times, rng = sweep["echo"], sweep["azimuth_deg"], sweep["time"], sweep["range_m"]
        spokes = echo.shape[0]
        dt = float(times[1] - times[0]) if spokes > 1 else 0.0
        t_ns = ns_of(float(times[0]))
        echoes = echo.astype(np.float32) / np.float32(15.0)
        msg = make("marine_sensor_msgs/msg/RadarSector", header=header(t_ns, "radar"),
                   angle_start=float(-math.radians(az[0])), angle_increment=float(-2.0 * math.pi / spokes),
                   time_increment=duration(dt), scan_time=duration(dt * spokes), range_min=float(rng[0]),
                   range_max=float(rng[-1]),
                   intensities=[radar_echo(echoes=row) for row in echoes])
        yield BagMessage(t_ns, "/radar/sector", "marine_sensor_msgs/msg/RadarSector", msg)
        picture = ppi_dir / f"{path.stem}.png"
        if picture.is_file():
            image = make("sensor_msgs/msg/CompressedImage", header=header(t_ns, "radar"), format="png",
                         data=np.frombuffer(picture.read_bytes(), dtype=np.uint8))
            yield BagMessage(t_ns, "/radar/image/compressed", "sensor_msgs/msg/CompressedImage", image)


def _ais_times(recording: Path) -> Iterator[tuple[float | None, int | None, str]]:
    """(reception time s since start, or None; TAG second, or None; sentence) of every AIS line.

    From ``ais/ais_received.jsonl`` (exact reception times) where it exists, else from the TAG
    blocks of ``ais/ais.nmea`` (whole seconds; older recordings).
    """
    received = recording / "ais" / "ais_received.jsonl"
    if received.is_file():
        with open(received, encoding="utf-8") as handle:
            for line in handle:
                row = json.loads(line)
                yield float(row["t"]), None, row["sentence"]
        return
    tagged = recording / AIS_NMEA
    if tagged.is_file():
        with open(tagged, encoding="ascii") as handle:
            for line in handle:
                tag, sentence = line.rstrip("\r\n")[1:].split("\\", 1)
                yield None, int(tag.split("*")[0][2:]), sentence


def ais_sentences(recording: Path, ns_of: NsOf) -> Iterator[BagMessage]:
    """``/ais/nmea``: one ``nmea_msgs/Sentence`` per ``!AIVDM`` sentence, stamped at its reception time."""
    for t_s, unix_s, sentence in _ais_times(recording):
        t_ns = ns_of(t_s) if t_s is not None else unix_s * 1_000_000_000
        yield BagMessage(t_ns, "/ais/nmea", "nmea_msgs/msg/Sentence",
                         make("nmea_msgs/msg/Sentence", header=header(t_ns, "ais"), sentence=sentence))
