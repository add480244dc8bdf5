"""Message types of the bag: the ROS 2 Humble typestore plus the definitions it lacks, and builders.

The typestore is rosbags' ROS 2 Humble store with these registered from their ``.msg`` text
(the text is also embedded in the bag, so any reader decodes them without the packages):

- ``marine_sensor_msgs/RadarSector`` and ``RadarEcho`` (apl-ocean-engineering/marine_msgs);
- ``nmea_msgs/Sentence`` (ros-drivers/nmea_msgs);
- ``vision_msgs/Detection3DArray`` and what it holds, as in vision_msgs 4 (ROS 2 Humble);
- ``foxglove_msgs/GeoJSON`` (foxglove/schemas, ROS 2 package foxglove_msgs);
- ``tdm_msgs/DetectedTarget(Array)``: the thesis's detected-target message (its Table 6.3) plus
  its sources, covariance and MMSI.
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import Any, NamedTuple

import numpy as np

__all__ = ["BagMessage", "RADAR_SECTOR_MSG", "RADAR_ECHO_MSG", "NMEA_SENTENCE_MSG", "DETECTED_TARGET_MSG",
           "DETECTED_TARGET_ARRAY_MSG", "GEOJSON_MSG", "VISION_MSGS", "typestore", "make", "header", "duration",
           "quaternion_from_matrix", "yaw_quaternion", "zyx_quaternions"]

RADAR_ECHO_MSG = "float32[] echoes\n"
RADAR_SECTOR_MSG = """std_msgs/Header header
float32 angle_start
float32 angle_increment
builtin_interfaces/Duration time_increment
builtin_interfaces/Duration scan_time
float32 range_min
float32 range_max
marine_sensor_msgs/RadarEcho[] intensities
"""
NMEA_SENTENCE_MSG = "std_msgs/Header header\nstring sentence\n"
#: The thesis's detected-target message (Table 6.3) plus its sources, covariance and MMSI (0 = none).
DETECTED_TARGET_MSG = """int32 target_id
string object_descriptor
float64 longitude
float64 latitude
float64 cog_deg
float64 sog_mps
float64 cross_section_m2
string[] sources
float64[4] position_covariance_m2
uint32 mmsi
"""
DETECTED_TARGET_ARRAY_MSG = "std_msgs/Header header\ntdm_msgs/DetectedTarget[] targets\n"
#: foxglove_msgs/GeoJSON: a GeoJSON document (RFC 7946) as text; Foxglove's Map panel draws it.
GEOJSON_MSG = "string geojson\n"
#: vision_msgs 4 (ROS 2 Humble): the 3D detection types.
VISION_MSGS = {
    "vision_msgs/msg/ObjectHypothesis": "string class_id\nfloat64 score\n",
    "vision_msgs/msg/ObjectHypothesisWithPose": ("vision_msgs/ObjectHypothesis hypothesis\n"
                                                  "geometry_msgs/PoseWithCovariance pose\n"),
    "vision_msgs/msg/BoundingBox3D": "geometry_msgs/Pose center\ngeometry_msgs/Vector3 size\n",
    "vision_msgs/msg/Detection3D": ("std_msgs/Header header\nvision_msgs/ObjectHypothesisWithPose[] results\n"
                                    "vision_msgs/BoundingBox3D bbox\nstring id\n"),
    "vision_msgs/msg/Detection3DArray": "std_msgs/Header header\nvision_msgs/Detection3D[] detections\n",
}


class BagMessage(NamedTuple):
    """One message to write: log time (ns since the UNIX epoch), topic, type and the message object."""

    t_ns: int
    topic: str
    msgtype: str
    msg: Any


@lru_cache(maxsize=1)
def typestore():
    """The ROS 2 Humble typestore with the definitions above registered (built once)."""
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE)
    types = {}
    for text, name in ((RADAR_ECHO_MSG, "marine_sensor_msgs/msg/RadarEcho"),
                       (RADAR_SECTOR_MSG, "marine_sensor_msgs/msg/RadarSector"),
                       (NMEA_SENTENCE_MSG, "nmea_msgs/msg/Sentence"),
                       (DETECTED_TARGET_MSG, "tdm_msgs/msg/DetectedTarget"),
                       (DETECTED_TARGET_ARRAY_MSG, "tdm_msgs/msg/DetectedTargetArray"),
                       (GEOJSON_MSG, "foxglove_msgs/msg/GeoJSON"), *((t, n) for n, t in VISION_MSGS.items())):
        types.update(get_types_from_msg(text, name))
    store.register(types)
    return store


_NUMPY = {"bool": np.bool_, "int8": np.int8, "uint8": np.uint8, "byte": np.uint8, "char": np.uint8,
          "int16": np.int16, "uint16": np.uint16, "int32": np.int32, "uint32": np.uint32, "int64": np.int64,
          "uint64": np.uint64, "float32": np.float32, "float64": np.float64}


def _default(kind):
    """Default value of a field description of the typestore (zeros, empty strings and sequences)."""
    node, detail = kind
    nodetype = _nodetype()
    if node == nodetype.BASE:
        name = detail[0]
        return "" if name == "string" else False if name == "bool" else 0.0 if name.startswith("float") else 0
    if node == nodetype.NAME:
        return make(detail)
    if node == nodetype.ARRAY:
        (sub, size) = detail
        if sub[0] == nodetype.BASE and sub[1][0] in _NUMPY:
            return np.zeros(size, dtype=_NUMPY[sub[1][0]])
        return [_default(sub) for _ in range(size)]
    sub = detail[0]
    if sub[0] == nodetype.BASE and sub[1][0] in _NUMPY:
        return np.zeros(0, dtype=_NUMPY[sub[1][0]])
    return []


@lru_cache(maxsize=1)
def _nodetype():
    """rosbags' field node types (imported on first use, as the typestore is)."""
    from rosbags.interfaces import Nodetype

    return Nodetype


@lru_cache(maxsize=None)
def _fields(msgtype: str) -> tuple[type, tuple, dict]:
    """A message type's class, its (name, kind) fields, and the defaults that can be shared (numbers, strings)."""
    store = typestore()
    _, fields = store.fielddefs[msgtype]
    shared = {name: _default(kind) for name, kind in fields if kind[0] == _nodetype().BASE}
    return store.types[msgtype], tuple(fields), shared


def message_class(msgtype: str) -> type:
    """The class of ``msgtype`` (``pkg/msg/Name``), to build many small messages whose every field is given."""
    return _fields(msgtype)[0]


def make(msgtype: str, **values):
    """A message of ``msgtype`` (``pkg/msg/Name``) with the given fields and every other field at its default.

    Numbers and strings at their defaults are shared between messages (immutable); nested messages
    and arrays are made afresh for each.
    """
    cls, fields, shared = _fields(msgtype)
    args = {}
    for name, kind in fields:
        if name in values:
            args[name] = values[name]
        elif name in shared:
            args[name] = shared[name]
        else:
            args[name] = _default(kind)
    return cls(**args)


def header(t_ns: int, frame: str):
    """``std_msgs/Header`` stamped ``t_ns`` (ns since the UNIX epoch) in ``frame``."""
    stamp = make("builtin_interfaces/msg/Time", sec=int(t_ns // 1_000_000_000), nanosec=int(t_ns % 1_000_000_000))
    return make("std_msgs/msg/Header", stamp=stamp, frame_id=frame)


def duration(seconds: float):
    """``builtin_interfaces/Duration`` of ``seconds`` (rounded to the nanosecond)."""
    ns = int(round(seconds * 1e9))
    return make("builtin_interfaces/msg/Duration", sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def point(x: float, y: float, z: float, msgtype: str = "geometry_msgs/msg/Point"):
    """A Point (or Vector3 with ``msgtype``) of three floats."""
    return make(msgtype, x=float(x), y=float(y), z=float(z))


def quaternion(q) -> Any:
    """``geometry_msgs/Quaternion`` of ``q`` = (x, y, z, w)."""
    return make("geometry_msgs/msg/Quaternion", x=float(q[0]), y=float(q[1]), z=float(q[2]), w=float(q[3]))


def pose(x: float, y: float, z: float, q) -> Any:
    """``geometry_msgs/Pose`` at (x, y, z) m with orientation ``q`` = (x, y, z, w)."""
    return make("geometry_msgs/msg/Pose", position=point(x, y, z), orientation=quaternion(q))


def yaw_quaternion(yaw_rad: float) -> tuple[float, float, float, float]:
    """(x, y, z, w) of a rotation by ``yaw_rad`` about z."""
    return 0.0, 0.0, math.sin(yaw_rad / 2.0), math.cos(yaw_rad / 2.0)


def zyx_quaternions(yaw_rad: np.ndarray, pitch_rad: np.ndarray, roll_rad: np.ndarray) -> np.ndarray:
    """Quaternions of yaw about z, then pitch about y, then roll about x (intrinsic).

    Parameters
    ----------
    yaw_rad, pitch_rad, roll_rad : (N,) float
        Angles, rad.

    Returns
    -------
    (N, 4) float
        (x, y, z, w) per row.
    """
    cy, sy = np.cos(yaw_rad / 2), np.sin(yaw_rad / 2)
    cp, sp = np.cos(pitch_rad / 2), np.sin(pitch_rad / 2)
    cr, sr = np.cos(roll_rad / 2), np.sin(roll_rad / 2)
    return np.stack([sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy,
                     cr * cp * cy + sr * sp * sy], axis=-1)


def quaternion_from_matrix(rot: np.ndarray) -> tuple[float, float, float, float]:
    """(x, y, z, w) of a (3, 3) rotation matrix."""
    from scipy.spatial.transform import Rotation

    x, y, z, w = Rotation.from_matrix(rot).as_quat()
    return float(x), float(y), float(z), float(w)
