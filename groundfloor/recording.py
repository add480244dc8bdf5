"""The recording contract: what raysim writes and the TDM reads (docs/formats.md).

One place for both wings: the file names of a recording directory, the arrays of its sweep files
(names, dtypes, axes, bounds), the manifest's format tag, and :class:`RecordingDescription`, a
typed description of a recording (start time, duration, sensor periods, ranges and mounts) built
from its ``manifest.json`` and resolved ``scenario.yaml``. raysim's writers write by it
(``SweepSchema.conform`` before each sweep file); the TDM's checked readers (``tdm.recording``)
check by it. Nothing here reads a file: the checks of untrusted input (bounds, types, the one-line
errors) are the TDM's, and a description is built from values those checks have passed.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from datetime import datetime, timezone

import numpy as np

from groundfloor.frames import Mount

__all__ = ["AIS_NMEA", "ArraySpec", "FORMAT", "FORMAT_VERSION", "LAND", "LIDAR_PCAP", "LIDAR_SWEEP", "LIDAR_SWEEPS", "MANIFEST",
           "OWNSHIP", "RADAR_SWEEP", "RADAR_SWEEPS", "SCENARIO", "SCHEMAS", "SWEEP_DIRS", "SweepSchema", "TRUTH",
           "LidarDescription", "RadarDescription", "RecordingDescription", "parse_start_time", "sweep_file_name"]

# ----------------------------------------------------------------------------- files

#: ``manifest.json: format`` and the newest ``format_version`` (readers accept 1..FORMAT_VERSION).
FORMAT = "raysim-recording"
FORMAT_VERSION = 1

MANIFEST = "manifest.json"
SCENARIO = "scenario.yaml"
OWNSHIP = "ownship.jsonl"
TRUTH = "truth.jsonl"
LIDAR_PCAP = "lidar/hdl32e.pcap"
LIDAR_SWEEPS = "lidar/sweeps"
RADAR_SWEEPS = "radar/sweeps"
AIS_NMEA = "ais/ais.nmea"
#: The recording's land (the chart's land mask, written when the scenario has land): a GeoJSON
#: FeatureCollection (RFC 7946, WGS84 lon/lat) of Polygon/MultiPolygon features whose properties are
#: ``id`` (the land object's id in manifest.json), ``name``, ``height_m`` and ``material``.
LAND = "land.geojson"
#: Sweep directory of each sensor, relative to the recording.
SWEEP_DIRS = {"lidar": LIDAR_SWEEPS, "radar": RADAR_SWEEPS}


def sweep_file_name(number: int) -> str:
    """``NNNNNN.npz``: the file of sweep (revolution) ``number``."""
    return f"{number:06d}.npz"


# ----------------------------------------------------------------------------- sweep arrays

@dataclass(frozen=True)
class ArraySpec:
    """One array of a sweep file.

    Attributes
    ----------
    name, dtype : str
        Array name and its dtype (``np.dtype`` text, native byte order; readers accept either order).
    axes : tuple of str
        Name of each dimension; arrays sharing a name share its length.
    required : bool
        Must be in every file (else only checked when present).
    low, high : float, optional
        Bounds of the values (checked when the array is loaded).
    ascending : bool
        Values must increase strictly.
    """

    name: str
    dtype: str
    axes: tuple[str, ...]
    required: bool = True
    low: float | None = None
    high: float | None = None
    ascending: bool = False


@dataclass(frozen=True)
class SweepSchema:
    """The arrays of one sensor's sweep files."""

    sensor: str
    arrays: tuple[ArraySpec, ...]

    def spec(self, name: str) -> ArraySpec | None:
        return next((a for a in self.arrays if a.name == name), None)

    def conform(self, arrays: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """``arrays`` unchanged (same order, same objects) if a writer's sweep keeps the contract.

        Every required array is there, every array is one of the schema's with its dtype and number
        of dimensions; else ``ValueError`` (a writer's bug, never a reader's concern).
        """
        for spec in self.arrays:
            if spec.required and spec.name not in arrays:
                raise ValueError(f"{self.sensor} sweep: array {spec.name} missing")
        for name, array in arrays.items():
            spec = self.spec(name)
            if spec is None:
                raise ValueError(f"{self.sensor} sweep: array {name} is not in the contract")
            if array.dtype != np.dtype(spec.dtype) or array.ndim != len(spec.axes):
                raise ValueError(f"{self.sensor} sweep: {name} is {array.dtype} {array.shape}, the contract says "
                                 f"{spec.dtype} [{', '.join(spec.axes)}]")
        return arrays


_P = ("points",)
_XYZ = {"low": -1.0e4, "high": 1.0e4}  # m: a LiDAR measures to 100-300 m
_DEG = {"low": -360.0, "high": 720.0}  # deg: the format's [0, 360), with room for another convention
LIDAR_SWEEP = SweepSchema("lidar", (
    ArraySpec("x", "float32", _P, **_XYZ), ArraySpec("y", "float32", _P, **_XYZ), ArraySpec("z", "float32", _P, **_XYZ),
    ArraySpec("intensity", "uint8", _P), ArraySpec("ring", "uint8", _P, high=31), ArraySpec("time", "float64", _P),
    ArraySpec("azimuth_deg", "float32", _P, **_DEG),
    ArraySpec("object_id", "int32", _P, required=False, low=-1),
    ArraySpec("return_source", "uint8", _P, required=False), ArraySpec("return_index", "uint8", _P, required=False),
))
RADAR_SWEEP = SweepSchema("radar", (
    ArraySpec("echo", "uint8", ("spokes", "samples"), high=15),
    ArraySpec("azimuth_deg", "float32", ("spokes",), **_DEG), ArraySpec("heading_deg", "float32", ("spokes",), **_DEG),
    ArraySpec("time", "float64", ("spokes",)),
    ArraySpec("range_m", "float32", ("samples",), low=0.0, high=1.0e7, ascending=True),
    ArraySpec("object_id", "int32", ("objects",), required=False),
    ArraySpec("object_spokes", "int32", ("objects",), required=False, low=0),
))
SCHEMAS = {"lidar": LIDAR_SWEEP, "radar": RADAR_SWEEP}


# ----------------------------------------------------------------------------- a recording, typed

def parse_start_time(text: str) -> float:
    """UNIX time (s) of an ISO 8601 ``start_time`` (``Z`` or an offset; none = UTC); ``ValueError`` if it is none."""
    when = datetime.fromisoformat(text.strip().replace("Z", "+00:00"))
    if when.tzinfo is None:
        when = when.replace(tzinfo=timezone.utc)
    return when.timestamp()


def _section(data: dict | None, *keys: str) -> dict:
    node = data or {}
    for key in keys:
        node = node.get(key) or {}
    return node


def _float(d: dict, key: str) -> float | None:
    value = d.get(key)
    return None if value is None else float(value)


def _enabled(d: dict) -> bool:
    return bool(d) and d.get("enabled", True) is not False


@dataclass(frozen=True)
class LidarDescription:
    """The LiDAR of a recording (``scenario.yaml: sensors.lidar``); None values: not stated."""

    enabled: bool = False
    rotation_hz: float | None = None
    range_min_m: float | None = None
    range_max_m: float | None = None
    beam_divergence_mrad: float | None = None
    mount: Mount = field(default_factory=Mount)

    @property
    def period_s(self) -> float | None:
        """One revolution, s."""
        return None if not self.rotation_hz else 1.0 / self.rotation_hz

    @classmethod
    def from_scenario(cls, scenario: dict | None) -> "LidarDescription":
        d = _section(scenario, "sensors", "lidar")
        return cls(_enabled(d), _float(d, "rotation_hz"), _float(d, "range_min_m"), _float(d, "range_max_m"),
                   _float(d, "beam_divergence_mrad"), Mount.from_dict(d.get("mount")))


@dataclass(frozen=True)
class RadarDescription:
    """The radar of a recording (``scenario.yaml: sensors.radar``); None values: not stated."""

    enabled: bool = False
    rpm: float | None = None
    range_m: float | None = None
    spokes: int | None = None
    samples: int | None = None
    beam_az_deg: float | None = None
    mount: Mount = field(default_factory=Mount)

    @property
    def period_s(self) -> float | None:
        """One antenna revolution, s."""
        return None if not self.rpm else 60.0 / self.rpm

    @classmethod
    def from_scenario(cls, scenario: dict | None) -> "RadarDescription":
        d = _section(scenario, "sensors", "radar")
        count = (lambda k: None if d.get(k) is None else int(d[k]))
        return cls(_enabled(d), _float(d, "rpm"), _float(d, "range_m"), count("spokes"), count("samples"),
                   _float(d, "beam_az_deg"), Mount.from_dict(d.get("mount")))


@dataclass(frozen=True)
class RecordingDescription:
    """A recording as both wings see it: when it starts and lasts, and what its sensors were.

    Built by :meth:`from_dicts` from the parsed ``manifest.json`` and ``scenario.yaml`` (the TDM
    builds it from its checked readers: ``tdm.recording.describe``). Periods and ranges are None
    where the scenario does not state them (each reader keeps its own default then).

    Attributes
    ----------
    start_time : str
        ``manifest.json: start_time`` (ISO 8601).
    start_time_unix_s : float
        The same as UNIX time, s.
    duration_s : float
        ``manifest.json: duration_s``.
    lidar, radar : LidarDescription, RadarDescription
        The sensors' rates, ranges and mounts.
    ais_range_m : float or None
        ``sensors.ais.range_m``.
    update_rate_hz : float or None
        ``tdm.update_rate_hz``: the TDM's output rate.
    """

    start_time: str
    start_time_unix_s: float
    duration_s: float
    lidar: LidarDescription = field(default_factory=LidarDescription)
    radar: RadarDescription = field(default_factory=RadarDescription)
    ais_range_m: float | None = None
    update_rate_hz: float | None = None

    @classmethod
    def from_dicts(cls, manifest: dict, scenario: dict | None) -> "RecordingDescription":
        """From a parsed manifest and scenario (both already checked by the reader)."""
        return cls(start_time=str(manifest["start_time"]), start_time_unix_s=parse_start_time(manifest["start_time"]),
                   duration_s=float(manifest["duration_s"]), lidar=LidarDescription.from_scenario(scenario),
                   radar=RadarDescription.from_scenario(scenario),
                   ais_range_m=_float(_section(scenario, "sensors", "ais"), "range_m"),
                   update_rate_hz=_float(_section(scenario, "tdm"), "update_rate_hz"))
