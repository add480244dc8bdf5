"""A recording as a ROS 2 bag (rosbag2 directory, MCAP storage, metadata version 8 for Humble).

Written with rosbags (pure Python) from the recording's own files, one message at a time
(memory flat): REFERENCE.md section 6 and DESIGN.md's recording contract.

| topic | type | from |
|---|---|---|
| /lidar/points | sensor_msgs/PointCloud2, velodyne driver layout (x y z intensity float32, ring uint16, time float32; point_step 22) | lidar/sweeps/*.npz, one per revolution |
| /radar/sector | marine_sensor_msgs/RadarSector (registered from its .msg text) | radar/sweeps/*.npz, one per revolution |
| /ais/nmea | nmea_msgs/Sentence | ais/ais.nmea, one per sentence |
| /ownship/fix | sensor_msgs/NavSatFix | ownship.jsonl |
| /ownship/pose | geometry_msgs/PoseStamped (frame map, local ENU) | ownship.jsonl |
| /tf_static | tf2_msgs/TFMessage: base_link -> lidar, base_link -> radar | the scenario's mounts |
| /tf | tf2_msgs/TFMessage: map -> base_link | ownship.jsonl (10 Hz) |
| /truth/objects | visualization_msgs/MarkerArray: a box per object | truth.jsonl (1 Hz) |
| /tdm/detected_targets | tdm_msgs/DetectedTargetArray (registered from its .msg text) | tdm/detected_targets.jsonl, one per epoch (when the TDM ran) |

Stamps are the scenario's UTC start plus each message's time; the bag's own time stamp of a
message is its header stamp.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from raysim.recording.jsonl import every, truth_epochs
from raysim.recording.pointclouds import PCD_DTYPE, velodyne_points

__all__ = ["write_rosbag", "RADAR_SECTOR_MSG", "RADAR_ECHO_MSG", "NMEA_SENTENCE_MSG", "DETECTED_TARGET_MSG",
           "DETECTED_TARGET_ARRAY_MSG", "POINT_STEP"]

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
POINT_STEP = PCD_DTYPE.itemsize  # velodyne_pointcloud XYZIRT: 4 x float32, uint16 ring, float32 time: 22


def _typestore():
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE)
    types = {}
    types.update(get_types_from_msg(RADAR_ECHO_MSG, "marine_sensor_msgs/msg/RadarEcho"))
    types.update(get_types_from_msg(RADAR_SECTOR_MSG, "marine_sensor_msgs/msg/RadarSector"))
    types.update(get_types_from_msg(NMEA_SENTENCE_MSG, "nmea_msgs/msg/Sentence"))
    types.update(get_types_from_msg(DETECTED_TARGET_MSG, "tdm_msgs/msg/DetectedTarget"))
    types.update(get_types_from_msg(DETECTED_TARGET_ARRAY_MSG, "tdm_msgs/msg/DetectedTargetArray"))
    store.register(types)
    return store


_NUMPY = {"bool": np.bool_, "int8": np.int8, "uint8": np.uint8, "byte": np.uint8, "char": np.uint8,
          "int16": np.int16, "uint16": np.uint16, "int32": np.int32, "uint32": np.uint32, "int64": np.int64,
          "uint64": np.uint64, "float32": np.float32, "float64": np.float64}


def _default(store, kind):
    """Default value of a field description of the typestore (zeros, empty strings and sequences)."""
    from rosbags.interfaces import Nodetype

    node, detail = kind
    if node == Nodetype.BASE:
        name = detail[0]
        return "" if name == "string" else False if name == "bool" else 0.0 if name.startswith("float") else 0
    if node == Nodetype.NAME:
        return make(store, detail)
    if node == Nodetype.ARRAY:
        (sub, size) = detail
        if sub[0] == Nodetype.BASE and sub[1][0] in _NUMPY:
            return np.zeros(size, dtype=_NUMPY[sub[1][0]])
        return [_default(store, sub) for _ in range(size)]
    sub = detail[0]
    if sub[0] == Nodetype.BASE and sub[1][0] in _NUMPY:
        return np.zeros(0, dtype=_NUMPY[sub[1][0]])
    return []


def make(store, msgtype: str, **values):
    """A message of ``msgtype`` with the given fields and every other field at its default."""
    _, fields = store.fielddefs[msgtype]
    args = {name: values[name] if name in values else _default(store, kind) for name, kind in fields}
    return store.types[msgtype](**args)


def _stamp(store, t_ns: int):
    Time = store.types["builtin_interfaces/msg/Time"]
    return Time(sec=int(t_ns // 1_000_000_000), nanosec=int(t_ns % 1_000_000_000))


def _header(store, t_ns: int, frame: str):
    Header = store.types["std_msgs/msg/Header"]
    return Header(stamp=_stamp(store, t_ns), frame_id=frame)


def _duration(store, seconds: float):
    Duration = store.types["builtin_interfaces/msg/Duration"]
    ns = int(round(seconds * 1e9))
    return Duration(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def write_rosbag(recording: Path, scenario, out: Path | None = None) -> dict:
    """Write ``recording/rosbag`` (or ``out``) from the recording's files; returns message counts per topic.

    Parameters
    ----------
    recording : Path
        A (staged) recording directory holding the sensor files.
    scenario : raysim.scenario.Scenario
        Its resolved scenario (start time, mounts).
    """
    from rosbags.rosbag2 import StoragePlugin, Writer

    from raysim.sensors.lidar import mount_transform

    recording = Path(recording)
    out = Path(out) if out is not None else recording / "rosbag"
    store = _typestore()
    t0_ns = int(round(scenario.start_time.timestamp() * 1e9))
    counts: dict[str, int] = {}

    def ns(t_s: float) -> int:
        return t0_ns + int(round(t_s * 1e9))

    with Writer(out, version=8, storage_plugin=StoragePlugin.MCAP) as writer:
        conns = {}

        def put(topic: str, msgtype: str, t_ns: int, msg) -> None:
            if topic not in conns:
                conns[topic] = writer.add_connection(topic, msgtype, typestore=store)
            writer.write(conns[topic], t_ns, store.serialize_cdr(msg, msgtype))
            counts[topic] = counts.get(topic, 0) + 1

        # static transforms: base_link -> sensor frames (mounts, body frame FLU)
        T = store.types
        transforms = []
        for frame, sensor in (("lidar", scenario.sensors.lidar), ("radar", scenario.sensors.radar)):
            rot, trans = mount_transform(sensor.mount)
            q = _quaternion(rot)
            transforms.append(T["geometry_msgs/msg/TransformStamped"](
                header=_header(store, t0_ns, "base_link"), child_frame_id=frame,
                transform=T["geometry_msgs/msg/Transform"](
                    translation=T["geometry_msgs/msg/Vector3"](x=float(trans[0]), y=float(trans[1]), z=float(trans[2])),
                    rotation=T["geometry_msgs/msg/Quaternion"](x=q[0], y=q[1], z=q[2], w=q[3]))))
        put("/tf_static", "tf2_msgs/msg/TFMessage", t0_ns, T["tf2_msgs/msg/TFMessage"](transforms=transforms))

        PointField = T["sensor_msgs/msg/PointField"]
        fields = [PointField(name=n, offset=o, datatype=d, count=1)
                  for n, o, d in (("x", 0, 7), ("y", 4, 7), ("z", 8, 7), ("intensity", 12, 7), ("ring", 16, 4),
                                  ("time", 18, 7))]
        for path in sorted((recording / "lidar" / "sweeps").glob("*.npz")):
            with np.load(path) as sweep:
                points = velodyne_points(sweep)
                n = points.size
                t_ns = ns(float(sweep["time"].min()) if n else 0.0)
            msg = T["sensor_msgs/msg/PointCloud2"](
                header=_header(store, t_ns, "lidar"), height=1, width=n, fields=fields, is_bigendian=False,
                point_step=POINT_STEP, row_step=POINT_STEP * n, data=points.view(np.uint8), is_dense=True)
            put("/lidar/points", "sensor_msgs/msg/PointCloud2", t_ns, msg)

        Echo = T["marine_sensor_msgs/msg/RadarEcho"]
        for path in sorted((recording / "radar" / "sweeps").glob("*.npz")):
            with np.load(path) as sweep:
                echo, az, times, rng = sweep["echo"], sweep["azimuth_deg"], sweep["time"], sweep["range_m"]
            spokes = echo.shape[0]
            dt = float(times[1] - times[0]) if spokes > 1 else 0.0
            t_ns = ns(float(times[0]))
            msg = T["marine_sensor_msgs/msg/RadarSector"](
                header=_header(store, t_ns, "radar"), angle_start=float(-math.radians(az[0])),
                angle_increment=float(-2.0 * math.pi / spokes), time_increment=_duration(store, dt),
                scan_time=_duration(store, dt * spokes), range_min=float(rng[0]), range_max=float(rng[-1]),
                intensities=[Echo(echoes=(row.astype(np.float32) / 15.0)) for row in echo])
            put("/radar/sector", "marine_sensor_msgs/msg/RadarSector", t_ns, msg)

        ais = recording / "ais" / "ais.nmea"
        if ais.is_file():
            with open(ais, encoding="ascii") as handle:
                for line in handle:
                    tag, sentence = line.rstrip("\n")[1:].split("\\", 1)
                    t_ns = int(tag.split("*")[0][2:]) * 1_000_000_000
                    put("/ais/nmea", "nmea_msgs/msg/Sentence", t_ns,
                        T["nmea_msgs/msg/Sentence"](header=_header(store, t_ns, "ais"), sentence=sentence))

        own = recording / "ownship.jsonl"
        if own.is_file():
            step = max(1, int(round(scenario.sensors.nav.rate_hz / 10.0)))  # 10 Hz in the bag
            Status = T["sensor_msgs/msg/NavSatStatus"]
            with open(own, encoding="utf-8") as handle:
                for k, line in enumerate(handle):
                    if k % step:
                        continue
                    row = json.loads(line)
                    t_ns = ns(row["t"])
                    fix = T["sensor_msgs/msg/NavSatFix"](
                        header=_header(store, t_ns, "base_link"), status=Status(status=0, service=1),
                        latitude=row["lat"], longitude=row["lon"], altitude=row["z"],
                        position_covariance=np.zeros(9), position_covariance_type=0)
                    put("/ownship/fix", "sensor_msgs/msg/NavSatFix", t_ns, fix)
                    yaw = math.radians(90.0 - row["heading_deg"])
                    pose = T["geometry_msgs/msg/PoseStamped"](
                        header=_header(store, t_ns, "map"),
                        pose=T["geometry_msgs/msg/Pose"](
                            position=T["geometry_msgs/msg/Point"](x=row["x"], y=row["y"], z=row["z"]),
                            orientation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=math.sin(yaw / 2),
                                                                         w=math.cos(yaw / 2))))
                    put("/ownship/pose", "geometry_msgs/msg/PoseStamped", t_ns, pose)
                    # map -> base_link: body FLU axes from yaw, pitch (FLU: nose down positive) and roll
                    q = _quaternion_zyx(yaw, -math.radians(row["pitch_deg"]), math.radians(row["roll_deg"]))
                    tf = T["geometry_msgs/msg/TransformStamped"](
                        header=_header(store, t_ns, "map"), child_frame_id="base_link",
                        transform=T["geometry_msgs/msg/Transform"](
                            translation=T["geometry_msgs/msg/Vector3"](x=row["x"], y=row["y"], z=row["z"]),
                            rotation=T["geometry_msgs/msg/Quaternion"](x=q[0], y=q[1], z=q[2], w=q[3])))
                    put("/tf", "tf2_msgs/msg/TFMessage", t_ns, T["tf2_msgs/msg/TFMessage"](transforms=[tf]))

        truth = recording / "truth.jsonl"
        if truth.is_file():
            for t_s, rows in truth_epochs(truth, every(1.0)):
                t_ns = ns(t_s)
                markers = [_marker(store, t_ns, row) for row in rows]
                put("/truth/objects", "visualization_msgs/msg/MarkerArray", t_ns,
                    T["visualization_msgs/msg/MarkerArray"](markers=markers))

        targets = recording / "tdm" / "detected_targets.jsonl"
        if targets.is_file():
            Target = T["tdm_msgs/msg/DetectedTarget"]
            for t_s, rows in _epochs(targets):
                t_ns = ns(t_s)
                msgs = [Target(target_id=r["target_id"], object_descriptor=r["object_descriptor"],
                               longitude=r["longitude"], latitude=r["latitude"], cog_deg=r["cog_deg"],
                               sog_mps=r["sog_mps"], cross_section_m2=r["cross_section_m2"], sources=r["sources"],
                               position_covariance_m2=np.array(r["position_cov_m2"], dtype=np.float64).ravel(),
                               mmsi=r.get("mmsi") or 0) for r in rows]
                put("/tdm/detected_targets", "tdm_msgs/msg/DetectedTargetArray", t_ns,
                    T["tdm_msgs/msg/DetectedTargetArray"](header=_header(store, t_ns, "map"), targets=msgs))
    return counts


def _epochs(path: Path):
    """(t, rows) of a JSON-lines file whose lines come in groups of equal ``t``."""
    t_cur, rows = None, []
    with open(path, encoding="utf-8") as handle:
        for line in handle:
            row = json.loads(line)
            if rows and row["t"] != t_cur:
                yield t_cur, rows
                rows = []
            t_cur = row["t"]
            rows.append(row)
    if rows:
        yield t_cur, rows


#: marker colours (r, g, b) per truth kind
KIND_COLOURS = {"ownship": (0.2, 0.6, 1.0), "ship": (1.0, 0.4, 0.2), "iceberg": (0.85, 0.95, 1.0),
                "buoy": (1.0, 0.85, 0.0), "mesh": (0.6, 0.6, 0.6)}


def _marker(store, t_ns: int, row: dict):
    """A CUBE of the object's length, beam and height at its truth pose (frame map), text = its name."""
    T = store.types
    yaw = math.radians(90.0 - row["heading_deg"])
    r, g, b = KIND_COLOURS.get(row["kind"], (0.6, 0.6, 0.6))
    return make(store, "visualization_msgs/msg/Marker", header=_header(store, t_ns, "map"), ns=row["kind"], id=int(row["id"]),
                type=1, action=0,
                pose=T["geometry_msgs/msg/Pose"](
                    position=T["geometry_msgs/msg/Point"](x=row["x"], y=row["y"], z=row["height_m"] / 2.0),
                    orientation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))),
                scale=T["geometry_msgs/msg/Vector3"](x=max(row["length_m"], 0.1), y=max(row["beam_m"], 0.1),
                                                     z=max(row["height_m"], 0.1)),
                color=T["std_msgs/msg/ColorRGBA"](r=r, g=g, b=b, a=0.6), lifetime=_duration(store, 1.5),
                text=row["name"])


def _quaternion_zyx(yaw_rad: float, pitch_rad: float, roll_rad: float) -> tuple[float, float, float, float]:
    """(x, y, z, w) of the rotation yaw about z, then pitch about y, then roll about x (intrinsic)."""
    cy, sy = math.cos(yaw_rad / 2), math.sin(yaw_rad / 2)
    cp, sp = math.cos(pitch_rad / 2), math.sin(pitch_rad / 2)
    cr, sr = math.cos(roll_rad / 2), math.sin(roll_rad / 2)
    return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy,
            cr * cp * cy + sr * sp * sy)


def _quaternion(rot: np.ndarray) -> tuple[float, float, float, float]:
    """(x, y, z, w) of a rotation matrix."""
    from scipy.spatial.transform import Rotation

    x, y, z, w = Rotation.from_matrix(rot).as_quat()
    return float(x), float(y), float(z), float(w)
