"""``--foxglove PORT``: the live session on a Foxglove WebSocket server (foxglove-sdk), without ROS.

Foxglove's own schemas on the bag's topic names (docs/formats.md, rosbag/), so the panels of
docs/foxglove_layout.json find them: ``/lidar/points`` (PointCloud, each revolution in the
``lidar`` frame), ``/radar/image/compressed`` (the revolution's PPI as a PNG), ``/truth/objects``
(SceneUpdate, a box per object in ``map``) and ``/truth/geojson`` at 1 Hz, ``/ownship/fix``
(LocationFix, for the Map panel) at 1 Hz, ``/tdm/markers`` and ``/tdm/geojson`` with each
epoch's detected targets, and ``/tf`` (FrameTransforms: ``map`` -> ``base_link`` from the own ship's
navigation, ``base_link`` -> ``lidar`` and ``radar`` from the mounts) at 10 Hz, so the 3D panel puts the
cloud where the boxes are. Everything is logged at its scenario time on the session's clock,
as it becomes due; the sweeps are read from the live working recording (:mod:`raysim.live.targets`).

foxglove-sdk is the maintained implementation of the Foxglove WebSocket protocol and schemas; a
server of our own would have to track both.
"""

from __future__ import annotations

import json
import math
import queue
import threading
import time
from pathlib import Path
from typing import Callable

import numpy as np

from raysim.recording.jsonl import every, row_centre_lat_lon, row_centre_xy, truth_epochs

__all__ = ["FoxgloveView", "TOPICS"]

TOPICS = ("/lidar/points", "/radar/image/compressed", "/truth/objects", "/truth/geojson", "/ownship/fix",
          "/tdm/markers", "/tdm/geojson", "/tf")
#: Rate of the frame transforms map -> base_link (the own ship) and base_link -> lidar / radar (the mounts), Hz.
TF_RATE_HZ = 10.0
#: How often the view looks for what has become due, s.
POLL_S = 0.05


def _stamp(unix_s: float):
    from foxglove.messages import Timestamp

    sec = int(math.floor(unix_s))
    return Timestamp(sec=sec, nsec=int(round((unix_s - sec) * 1e9)) % 1_000_000_000)


class FoxgloveView(threading.Thread):
    """A Foxglove server on 127.0.0.1:port fed from the working recording and the live TDM (a bounded loop).

    Parameters
    ----------
    port : int
    folder : Path
        The working recording (its sweeps appear while the session runs).
    clock : callable
        The session's scenario clock, s (0 until it starts).
    start_unix_s : float
        UNIX time of scenario time 0.
    to_local : callable
        ``(lat_deg, lon_deg) -> (east_m, north_m)`` of the world's local frame (the targets' boxes).
    stop : threading.Event
    mounts : dict, optional
        Sensor frame name -> (rotation (3, 3), translation (3,) m), sensor to body (``/tf``).
    """

    def __init__(self, port: int, folder: Path, clock: Callable[[], float], start_unix_s: float,
                 to_local: Callable, stop: threading.Event, mounts: dict | None = None):
        super().__init__(name="live-foxglove", daemon=True)
        import foxglove

        self.server = foxglove.start_server(host="127.0.0.1", port=port, name="raysim live")
        self.port = self.server.port
        self.folder, self.clock, self.start_unix_s, self.stop = Path(folder), clock, start_unix_s, stop
        self.to_local = to_local
        self.mounts = mounts or {}
        self._next: dict[str, tuple[int, float, dict]] = {}  # per sensor: the next sweep, read, not yet due
        self.targets: queue.Queue = queue.Queue()
        self.error: BaseException | None = None
        self._channels()

    def _channels(self) -> None:
        from foxglove.channels import (CompressedImageChannel, GeoJsonChannel, LocationFixChannel, PointCloudChannel,
                                       SceneUpdateChannel)

        self.lidar = PointCloudChannel("/lidar/points")
        self.radar = CompressedImageChannel("/radar/image/compressed")
        self.truth = SceneUpdateChannel("/truth/objects")
        self.truth_geo = GeoJsonChannel("/truth/geojson")
        self.fix = LocationFixChannel("/ownship/fix")
        self.tdm = SceneUpdateChannel("/tdm/markers")
        self.tdm_geo = GeoJsonChannel("/tdm/geojson")
        from foxglove.channels import FrameTransformsChannel

        self.tf = FrameTransformsChannel("/tf")

    def close(self) -> None:
        self.server.stop()

    def run(self) -> None:
        try:
            truth = truth_epochs(self.folder / "truth.jsonl", every(1.0))
            next_truth = next(truth, None)
            own, next_fix = self._ownship_rows(), -math.inf
            sweeps = {"lidar": 0, "radar": 0}
            while not self.stop.is_set():
                now = self.clock()
                while next_truth is not None and next_truth[0] <= now:
                    self._log_truth(*next_truth)
                    next_truth = next(truth, None)
                while own and own[0]["t"] <= now:
                    row = own.pop(0)
                    self._log_tf(row)
                    if row["t"] >= next_fix:
                        self._log_fix(row)
                        next_fix = row["t"] + 1.0
                for sensor in sweeps:
                    sweeps[sensor] += self._log_sweep(sensor, sweeps[sensor], now)
                while not self.targets.empty():
                    self._log_targets(*self.targets.get_nowait())
                time.sleep(POLL_S)
        except BaseException as exc:  # reported by the session
            self.error = exc

    def _ns(self, t_s: float) -> int:
        return int(round((self.start_unix_s + t_s) * 1e9))

    def _ownship_rows(self) -> list[dict]:
        path = self.folder / "ownship.jsonl"
        rows, last = [], -math.inf
        for line in path.read_text(encoding="utf-8").splitlines():
            row = json.loads(line)
            if row["t"] >= last + 1.0 / TF_RATE_HZ - 1e-9:  # the transforms' rate (the map's fix: 1 Hz of them)
                rows.append(row)
                last = row["t"]
        return rows

    def _log_fix(self, row: dict) -> None:
        from foxglove.messages import LocationFix

        self.fix.log(LocationFix(timestamp=_stamp(self.start_unix_s + row["t"]), frame_id="base_link",
                                 latitude=row["lat"], longitude=row["lon"], altitude=0.0,
                                 heading=math.radians(row["heading_deg"])), log_time=self._ns(row["t"]))

    def _log_tf(self, row: dict) -> None:
        from foxglove.messages import FrameTransform, FrameTransforms, Quaternion, Vector3

        from raysim.recording.rosbag.msgs import quaternion_from_matrix, zyx_quaternions

        stamp = _stamp(self.start_unix_s + row["t"])
        q = zyx_quaternions(np.radians(90.0 - row["heading_deg"]), -np.radians(row["pitch_deg"]),
                            np.radians(row["roll_deg"]))
        transforms = [FrameTransform(timestamp=stamp, parent_frame_id="map", child_frame_id="base_link",
                                     translation=Vector3(x=row["x"], y=row["y"], z=row["z"]),
                                     rotation=Quaternion(x=q[0], y=q[1], z=q[2], w=q[3]))]
        for name, (rot, trans) in self.mounts.items():
            x, y, z, w = quaternion_from_matrix(rot)
            transforms.append(FrameTransform(timestamp=stamp, parent_frame_id="base_link", child_frame_id=name,
                                             translation=Vector3(x=float(trans[0]), y=float(trans[1]), z=float(trans[2])),
                                             rotation=Quaternion(x=x, y=y, z=z, w=w)))
        self.tf.log(FrameTransforms(transforms=transforms), log_time=self._ns(row["t"]))

    def _log_truth(self, t_s: float, rows: list[dict]) -> None:
        entities = [self._box(t_s, f"{r['kind']}/{r['id']}", *row_centre_xy(r), r["heading_deg"],
                              (r["length_m"], r["beam_m"], r["height_m"]), (0.2, 0.8, 0.2)) for r in rows]
        self._scene(self.truth, t_s, entities)
        features = [{"type": "Feature", "geometry": {"type": "Point", "coordinates": list(row_centre_lat_lon(r)[::-1])},
                     "properties": {"name": r["name"], "kind": r["kind"], "id": r["id"]}} for r in rows]
        self._geojson(self.truth_geo, t_s, features)

    def _log_targets(self, t_s: float, records: list[dict]) -> None:
        lon = np.array([r["longitude"] for r in records], float)
        lat = np.array([r["latitude"] for r in records], float)
        x_m, y_m = self.to_local(lat, lon)
        entities = [self._box(t_s, f"target/{r['target_id']}", x, y, r["cog_deg"], (8.0, 8.0, 4.0), (1.0, 0.3, 0.1))
                    for r, x, y in zip(records, np.atleast_1d(x_m), np.atleast_1d(y_m))]
        self._scene(self.tdm, t_s, entities)
        features = [{"type": "Feature", "geometry": {"type": "Point", "coordinates": [r["longitude"], r["latitude"]]},
                     "properties": {"target_id": r["target_id"], "descriptor": r["object_descriptor"]}}
                    for r in records]
        self._geojson(self.tdm_geo, t_s, features)

    def _box(self, t_s: float, ident: str, x_m: float, y_m: float, heading_deg: float, size_m, rgb):
        from foxglove.messages import Color, CubePrimitive, Pose, Quaternion, SceneEntity, Vector3

        yaw = math.radians(90.0 - heading_deg)
        size = [max(float(v), 0.1) for v in size_m]
        cube = CubePrimitive(pose=Pose(position=Vector3(x=float(x_m), y=float(y_m), z=size[2] / 2.0),
                                       orientation=Quaternion(x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))),
                             size=Vector3(x=size[0], y=size[1], z=size[2]), color=Color(r=rgb[0], g=rgb[1], b=rgb[2], a=0.6))
        return SceneEntity(timestamp=_stamp(self.start_unix_s + t_s), frame_id="map", id=ident, cubes=[cube])

    def _scene(self, channel, t_s: float, entities: list) -> None:
        from foxglove.messages import SceneUpdate

        channel.log(SceneUpdate(entities=entities), log_time=self._ns(t_s))

    def _geojson(self, channel, t_s: float, features: list[dict]) -> None:
        from foxglove.messages import GeoJson

        channel.log(GeoJson(geojson=json.dumps({"type": "FeatureCollection", "features": features})),
                    log_time=self._ns(t_s))

    def _log_sweep(self, sensor: str, k: int, now_s: float) -> int:
        """Log sweep ``k`` of ``sensor`` if its file exists and its last time has come; 1 if logged.

        A sweep read before its time is kept (``self._next``), not read again at every poll.
        """
        held = self._next.get(sensor)
        if held is None or held[0] != k:
            path = self.folder / sensor / "sweeps" / f"{k:06d}.npz"
            if not path.exists():
                return 0
            with np.load(path) as sweep:
                arrays = {name: sweep[name] for name in sweep.files}
            held = self._next[sensor] = (k, float(np.max(arrays["time"])) if arrays["time"].size else 0.0, arrays)
        _, t_end, arrays = held
        if t_end > now_s:
            return 0
        del self._next[sensor]
        (self._log_cloud if sensor == "lidar" else self._log_ppi)(t_end, arrays)
        return 1

    def _log_cloud(self, t_s: float, sweep: dict) -> None:
        from foxglove.messages import PackedElementField, PackedElementFieldNumericType, PointCloud, Pose, Quaternion, Vector3

        xyzi = np.stack([sweep["x"], sweep["y"], sweep["z"], sweep["intensity"]], axis=1).astype(np.float32)
        f32 = PackedElementFieldNumericType.Float32
        fields = [PackedElementField(name=n, offset=4 * i, type=f32) for i, n in enumerate(("x", "y", "z", "intensity"))]
        self.lidar.log(PointCloud(timestamp=_stamp(self.start_unix_s + t_s), frame_id="lidar",
                                  pose=Pose(position=Vector3(x=0.0, y=0.0, z=0.0),
                                            orientation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0)),
                                  point_stride=16, fields=fields, data=xyzi.tobytes()), log_time=self._ns(t_s))

    def _log_ppi(self, t_s: float, sweep: dict) -> None:
        import io

        from foxglove.messages import CompressedImage

        from raysim.recording.ppi import ppi_image

        image = ppi_image(sweep["echo"], sweep["azimuth_deg"], sweep["heading_deg"], sweep["range_m"])
        buffer = io.BytesIO()
        image.save(buffer, format="PNG", compress_level=1)
        self.radar.log(CompressedImage(timestamp=_stamp(self.start_unix_s + t_s), frame_id="radar",
                                       data=buffer.getvalue(), format="png"), log_time=self._ns(t_s))
