"""Scenario files: the native YAML format of docs/scenario.md, loaded strictly into typed objects.

``load_scenario(path)`` parses with :func:`raysim.yaml_loader.read_yaml` (safe constructors
only; keys given twice, alias bombs and deep nesting refused), validates every key
(unknown keys, wrong types, NaN/inf, float32-collapsing and out-of-range values are errors
naming the key path), checks that referenced files are regular files
(:mod:`raysim.input_files`) and the cross-field rules (:mod:`raysim.scenario_checks`, with the
limits of :mod:`raysim.limits`), and returns a :class:`Scenario` whose derived defaults are
filled in (:func:`resolve`). ``dump_scenario`` writes
the resolved scenario back as YAML (the recording's ``scenario.yaml``).

Every field and its default is listed in docs/scenario.md (generated from this
module by ``python -m raysim.scenario --doc``; a test keeps them in sync).
"""

from __future__ import annotations

import dataclasses
import datetime as dt
import math
import sys
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

import yaml

from raysim import schema
from raysim.errors import InputError
from raysim.input_files import MAX_CSV_FILE_BYTES, MAX_MESH_FILE_BYTES, path_check
from raysim.limits import RESOLVE_CHECK, SIZE_CHECK
from raysim.schema import Context, param
from raysim.yaml_loader import read_yaml  # noqa: F401 (raysim.hilsim reads the thesis's files with it)

LatLon = tuple[float, float]

#: Positions further than this from the origin are rejected: the local frame
#: (transverse Mercator about the origin, flat sea) is meant for a local scene.
MAX_DISTANCE_FROM_ORIGIN_M = 50_000.0

#: Douglas sea state -> significant wave height upper bound, m (WMO sea state code 3700).
DOUGLAS_WAVE_HEIGHT_M = (0.0, 0.1, 0.5, 1.25, 2.5, 4.0, 6.0)

#: Own-ship wave motion defaults per Douglas sea state 0..6 for a ~11 m craft
#: (engineering defaults, unverified; override with own_ship.motion).
#: Heave amplitude about 0.35 x the significant wave height mid-band.
SEA_STATE_MOTION = {
    "roll_amplitude_deg": (0.0, 0.5, 1.5, 3.0, 5.0, 8.0, 12.0),
    "pitch_amplitude_deg": (0.0, 0.3, 0.8, 1.5, 2.5, 4.0, 6.0),
    "heave_amplitude_m": (0.0, 0.02, 0.1, 0.3, 0.65, 1.1, 1.75),
    "wave_period_s": (2.0, 2.0, 3.0, 4.0, 5.0, 6.5, 8.0),
}


def _lat_lon_check(value: LatLon) -> str | None:
    lat, lon = value
    if not -90.0 <= lat <= 90.0:
        return f"latitude must be within [-90, 90] deg, got {lat:g} (positions are [lat, lon])"
    if not -180.0 <= lon <= 180.0:
        return f"longitude must be within [-180, 180] deg, got {lon:g} (positions are [lat, lon])"
    return None


def _waypoints_check(value: tuple[LatLon, ...]) -> str | None:
    for i, wp in enumerate(value):
        message = _lat_lon_check(wp)
        if message:
            return f"waypoint {i}: {message}"
        if i and wp == value[i - 1]:
            return f"waypoint {i} repeats waypoint {i - 1}"
    return None


def _mmsi_check(value: int) -> str | None:
    if not 100_000_000 <= value <= 999_999_999:
        return f"an MMSI has exactly 9 digits, got {value}"
    return None


_MESH_FILE = path_check("mesh file", MAX_MESH_FILE_BYTES)


@dataclass(frozen=True, kw_only=True)
class Origin:
    lat: float = param(doc="Latitude of the local frame's origin, deg", ge=-90, le=90)
    lon: float = param(doc="Longitude of the local frame's origin, deg", ge=-180, le=180)


@dataclass(frozen=True, kw_only=True)
class Environment:
    sea_state: int = param(2, doc="Douglas sea state 0..6: sea clutter, foam, waves, own-ship motion", ge=0, le=6)
    wind_speed_mps: float = param(5.0, doc="True wind speed, m/s", ge=0, le=70)
    wind_from_deg: float = param(0.0, doc="Direction the wind blows from, compass deg", ge=0, lt=360)
    rain_mm_per_h: float = param(0.0, doc="Rain rate, mm/h (radar attenuation and clutter, LiDAR attenuation)", ge=0, le=300)
    fog_visibility_m: float | None = param(None, doc="Meteorological visibility in fog, m; null = no fog", gt=0, check=SIZE_CHECK)


@dataclass(frozen=True, kw_only=True)
class Route:
    waypoints: tuple[LatLon, ...] = param(doc="Waypoints [lat, lon], deg; one waypoint = anchored", min_items=1, check=_waypoints_check)
    speed_kn: float = param(0.0, doc="Speed through the water, knots", ge=0, le=60)
    at_end: Literal["continue", "stop", "loop"] = param("continue", doc="After the last waypoint: keep the last course, stop, or loop back to the first")
    heading_time_constant_s: float | None = param(
        None, doc="First-order heading response time constant in turns, s", gt=0, le=600,
        default_doc="0.1 s/m x length_m, clipped to [2, 60] s")


@dataclass(frozen=True, kw_only=True)
class WaveMotion:
    roll_amplitude_deg: float | None = param(None, doc="Wave-induced roll amplitude, deg", ge=0, le=45, default_doc="from sea_state (docs/scenario.md table)")
    roll_period_s: float | None = param(None, doc="Roll period, s", gt=0, le=60, default_doc="5 s (sea state 0-4), 6 s (5), 7 s (6)")
    pitch_amplitude_deg: float | None = param(None, doc="Pitch amplitude, deg (bow up positive)", ge=0, le=30, default_doc="from sea_state")
    pitch_period_s: float | None = param(None, doc="Pitch period, s", gt=0, le=60, default_doc="4 s")
    heave_amplitude_m: float | None = param(None, doc="Heave amplitude, m", ge=0, le=10, default_doc="from sea_state")
    heave_period_s: float | None = param(None, doc="Heave period, s", gt=0, le=60, default_doc="wave period of the sea state")


@dataclass(frozen=True, kw_only=True)
class OwnShip:
    name: str = param("odin", doc="Own-ship name")
    length_m: float = param(10.9, doc="Length overall, m (Odin: 10.9 m)", gt=0, le=400, check=SIZE_CHECK)
    beam_m: float | None = param(None, doc="Beam, m", gt=0, le=80, check=SIZE_CHECK, default_doc="length_m / (3.2 + 0.03 length_m)")
    mesh: Path | None = param(None, doc="Hull mesh file (body frame, metres); null = generated workboat", check=_MESH_FILE)
    material: str = param("grp", doc="Material of a mesh file's faces (raysim.materials)")
    route: Route | None = param(None, doc="Waypoint route (one of route / trajectory_csv / position)")
    trajectory_csv: Path | None = param(None, doc="CSV with t_s, lat, lon, heading_deg[, roll_deg, pitch_deg, heave_m]",
                                        check=path_check("trajectory CSV", MAX_CSV_FILE_BYTES))
    position: LatLon | None = param(None, doc="Fixed position [lat, lon], deg", check=_lat_lon_check)
    heading_deg: float = param(0.0, doc="Heading of a fixed own ship, compass deg", ge=0, lt=360)
    motion: WaveMotion = param(default_factory=WaveMotion, doc="Wave-induced roll, pitch and heave")


@dataclass(frozen=True, kw_only=True)
class Mount:
    x_m: float = param(0.0, doc="Forward of the own-ship origin, m", ge=-200, le=200)
    y_m: float = param(0.0, doc="Left of the own-ship origin, m", ge=-50, le=50)
    z_m: float = param(3.0, doc="Above the waterline, m", ge=-10, le=100)
    roll_deg: float = param(0.0, doc="Mount roll, deg", ge=-180, le=180)
    pitch_deg: float = param(0.0, doc="Mount pitch, deg (bow up positive)", ge=-90, le=90)
    yaw_deg: float = param(0.0, doc="Mount yaw, deg (clockwise from the bow)", ge=-180, le=360)


@dataclass(frozen=True, kw_only=True)
class Lidar:
    enabled: bool = param(True, doc="Render this sensor")
    model: Literal["HDL-32E"] = param("HDL-32E", doc="LiDAR model")
    rotation_hz: float = param(10.0, doc="Head rotation rate, Hz (HDL-32E: 5-20)", ge=5, le=20)
    range_max_m: float = param(100.0, doc="Maximum range, m (HDL-32E: 100 m; encoding limit 131.07 m)", gt=0, le=131.07, check=SIZE_CHECK)
    range_min_m: float = param(0.05, doc="Minimum range, m (HDL-32E returns from 5 cm; drivers often cut at 0.9 m)", ge=0, le=10)
    range_noise_m: float = param(0.008, doc="Range noise, 1 sigma, m (simulators use 0.007-0.008 m)", ge=0, le=1)
    return_mode: Literal["strongest", "last", "dual"] = param("strongest", doc="Return mode of the packets")
    detection_reflectance: float = param(0.10, doc="Apparent reflectance just detected at 100 m in clear air (link budget; unverified)", gt=0, le=1)
    beam_divergence_mrad: float = param(3.0, doc="Full beam divergence, mrad (Chrono uses 3 mrad; no official figure)", ge=0, le=50)
    sub_rays: Literal[1, 7, 19] = param(1, doc="Rays per beam: 1 = the beam axis only; 7 or 19 sample the divergence cone (edges give dual returns)")
    azimuth0_deg: float = param(0.0, doc="Head azimuth at t = 0, deg", ge=0, lt=360)
    position_packet_rate_hz: float = param(1.0, doc="Position packets (UDP 8308) per second (unverified)", ge=0, le=100)
    mount: Mount = param(default_factory=Mount, doc="Mounting on the own ship (body frame)")


@dataclass(frozen=True, kw_only=True)
class Radar:
    enabled: bool = param(True, doc="Render this sensor")
    model: Literal["broadband-4g", "broadband-3g"] = param("broadband-4g", doc="Radar model (Simrad/Navico Broadband class)")
    rpm: float = param(24.0, doc="Antenna rotation, revolutions per minute", gt=0, le=120)
    range_m: float = param(1852.0, doc="Range scale: distance of the last sample, m", ge=50, le=66_672)
    spokes: int = param(2048, doc="Spokes per revolution", ge=64, le=8192)
    samples: int = param(1024, doc="Samples per spoke", ge=64, le=4096)
    mount: Mount = param(default_factory=lambda: Mount(z_m=4.0), doc="Mounting on the own ship (body frame)")
    polarisation: Literal["HH", "VV"] = param("HH", doc="Polarisation (marine X-band sets are HH); sets the NRL clutter and K shape")
    gain_db: float = param(
        0.0, doc="Receiver gain re. the default setting, dB: every video level moves down by as much (the default "
        "threshold, 9.6 dB over noise, gives a false-alarm rate of about 1e-4)", ge=-30, le=30)
    sea_clutter_control_db: float = param(
        20.0, doc="Sea control (STC): attenuation at 100 m, rising 40 dB/decade to 0; 0 turns it off", ge=0, le=80)
    rain_clutter_control_m: float = param(
        0.0, doc="Rain control (FTC): range time constant of the log-video high-pass, m; 0 turns it off", ge=0)
    blanking_m: float = param(3.0, doc="Main-bang blanking: samples nearer than this read 0, m", ge=0)
    multipath: bool = param(True, doc="Two-ray interference of the direct and sea-reflected paths")
    earth_curvature: bool = param(True, doc="4/3-earth radar horizon: what lies below it is not seen")
    beam_az_deg: float = param(5.2, doc="Horizontal -3 dB beam width, deg (18 in dome)", gt=0, le=45)
    beam_el_deg: float = param(25.0, doc="Vertical -3 dB beam width, deg", gt=0, le=90)
    resolve_m: float = param(
        6.0, doc="Ray spacing across the beam at the range scale (or the horizon if nearer), m", gt=0, le=100,
        check=RESOLVE_CHECK)


@dataclass(frozen=True, kw_only=True)
class AisNoise:
    """The thesis's AIS noise parameters (appendix B.3), named as there without the ``AIS_`` prefix.

    The thesis's own names (``AIS_COG_measure_variance_deg2``, ...) are accepted too.
    """

    position_measure_variance_m2: float = param(5.0, aliases=("AIS_position_measure_variance_m2",),
        doc="White-noise variance of position, m^2", ge=0)
    cog_measure_variance_deg2: float = param(1.0, aliases=("AIS_COG_measure_variance_deg2",),
        doc="White-noise variance of COG, deg^2", ge=0)
    track_measure_variance_deg2: float = param(1.0, aliases=("AIS_track_measure_variance_deg2",),
        doc="White-noise variance of true heading, deg^2", ge=0)
    rot_measure_variance_deg2_pr_min2: float = param(2000.0, aliases=("AIS_ROT_measure_variance_deg2_pr_min2",),
        doc="White-noise variance of ROT, (deg/min)^2", ge=0)
    sog_measure_variance_knots2: float = param(0.5, aliases=("AIS_SOG_measure_variance_knots2",),
        doc="White-noise variance of SOG, kn^2", ge=0)
    position_bias_variance_m2: float = param(0.5, aliases=("AIS_position_bias_variance_m2",),
        doc="Gauss-Markov bias variance of position, m^2", ge=0)
    cog_bias_variance_deg2: float = param(0.5, aliases=("AIS_COG_bias_variance_deg2",),
        doc="Gauss-Markov bias variance of COG, deg^2", ge=0)
    track_bias_variance_deg2: float = param(0.5, aliases=("AIS_track_bias_variance_deg2",),
        doc="Gauss-Markov bias variance of heading, deg^2", ge=0)
    rot_bias_variance_deg2_pr_min2: float = param(500.0, aliases=("AIS_ROT_bias_variance_deg2_pr_min2",),
        doc="Gauss-Markov bias variance of ROT, (deg/min)^2", ge=0)
    sog_bias_variance_knots2: float = param(0.1, aliases=("AIS_SOG_bias_variance_knots2",),
        doc="Gauss-Markov bias variance of SOG, kn^2", ge=0)
    position_bias_time_constant_sec: float = param(20.0, aliases=("AIS_position_bias_time_constant_sec",),
        doc="Bias time constant of position, s", gt=0)
    cog_bias_time_constant_sec: float = param(10.0, aliases=("AIS_COG_bias_time_constant_sec",),
        doc="Bias time constant of COG, s", gt=0)
    track_bias_time_constant_sec: float = param(10.0, aliases=("AIS_track_bias_time_constant_sec",),
        doc="Bias time constant of heading, s", gt=0)
    rot_bias_time_constant_sec: float = param(10.0, aliases=("AIS_ROT_bias_time_constant_sec",),
        doc="Bias time constant of ROT, s", gt=0)
    sog_bias_time_constant_sec: float = param(10.0, aliases=("AIS_SOG_bias_time_constant_sec",),
        doc="Bias time constant of SOG, s", gt=0)


@dataclass(frozen=True, kw_only=True)
class Ais:
    enabled: bool = param(True, doc="Receive AIS")
    range_m: float = param(10_000.0, doc="Reception range, m", gt=0, le=200_000, check=SIZE_CHECK)
    antenna_height_m: float = param(5.0, doc="Height of the own ship's VHF antenna above the sea, m (radio horizon)", gt=0, le=100, check=SIZE_CHECK)
    radio_horizon: bool = param(True, doc="Limit reception to the VHF radio horizon 4.12 (sqrt(h_tx) + sqrt(h_rx)) km")
    noise: AisNoise = param(default_factory=AisNoise, doc="Transponder error model (thesis section 2.5)")


@dataclass(frozen=True, kw_only=True)
class Nav:
    enabled: bool = param(True, doc="Write the own-ship navigation solution")
    rate_hz: float = param(50.0, doc="Navigation output rate (ownship.jsonl), Hz", gt=0, le=200)
    nmea_rate_hz: float = param(1.0, doc="Rate of the GNSS/compass NMEA lines (nav/nav.nmea), Hz", gt=0, le=50)
    position_noise_m: float = param(0.1, doc="GNSS position white noise, standard deviation per axis, m", ge=0, le=100)
    position_bias_m: float = param(0.5, doc="GNSS position Gauss-Markov bias, standard deviation per axis, m", ge=0, le=100)
    position_bias_time_constant_s: float = param(300.0, doc="Time constant of the position bias, s", gt=0)
    velocity_noise_mps: float = param(0.02, doc="GNSS velocity white noise, standard deviation per axis, m/s", ge=0, le=10)
    heading_noise_deg: float = param(0.05, doc="Heading (INS/compass) white noise, standard deviation, deg", ge=0, le=10)
    heading_bias_deg: float = param(0.1, doc="Heading Gauss-Markov bias, standard deviation, deg", ge=0, le=10)
    heading_bias_time_constant_s: float = param(600.0, doc="Time constant of the heading bias, s", gt=0)
    attitude_noise_deg: float = param(0.02, doc="Roll and pitch white noise, standard deviation, deg", ge=0, le=10)
    geoid_separation_m: float = param(0.0, doc="EGM96 geoid height above the WGS84 ellipsoid at the scenario area, m: "
                                      "the GGA geoid separation field; the ellipsoidal altitude that receivers "
                                      "report is the GGA altitude plus this", ge=-120, le=120)


@dataclass(frozen=True, kw_only=True)
class Sensors:
    lidar: Lidar = param(default_factory=Lidar, doc="Velodyne HDL-32E")
    radar: Radar = param(default_factory=Radar, doc="Marine navigation radar")
    ais: Ais = param(default_factory=Ais, doc="AIS receiver")
    nav: Nav = param(default_factory=Nav, doc="Own-ship navigation (GNSS/INS)")

    def enabled_names(self) -> tuple[str, ...]:
        """Names of the enabled sensors, in a fixed order."""
        return tuple(f.name for f in dataclasses.fields(self) if getattr(self, f.name).enabled)


@dataclass(frozen=True, kw_only=True)
class Tdm:
    update_rate_hz: float = param(1.0, doc="Detected-target publishing rate, Hz", gt=0, le=50)


@dataclass(frozen=True, kw_only=True)
class Obstacle:
    name: str = param(doc="Unique name")
    kind: Literal["iceberg", "buoy", "mesh"] = param(doc="iceberg (generated), buoy (generated) or mesh (a file)")
    position: LatLon = param(doc="Position [lat, lon] of the body origin, deg", check=_lat_lon_check)
    heading_deg: float = param(0.0, doc="Heading of the body x axis, compass deg", ge=0, lt=360)
    radius_m: float | None = param(None, doc="Iceberg: waterline radius, m", gt=0, le=1000, check=SIZE_CHECK, default_doc="15 m (iceberg)")
    height_m: float | None = param(None, doc="Iceberg: height above water, m", gt=0, le=200, check=SIZE_CHECK, default_doc="0.5 x radius_m (iceberg)")
    seed: int | None = param(None, doc="Iceberg: shape seed", ge=0, default_doc="CRC-32 of the name (shape independent of the scenario seed)")
    mesh: Path | None = param(None, doc="Mesh file for kind mesh (body frame, metres)", check=_MESH_FILE)
    material: str | None = param(None, doc="Material of a mesh file's faces", default_doc="concrete (mesh)")


def _periods_check(value) -> str | None:
    for i, (start, end) in enumerate(value):
        if not start < end:
            return f"period {i}: start {start} must be before end {end}"
    return None


def _ais_text(limit: int):
    """Check of an AIS text field: the 6-bit character set and at most ``limit`` characters."""

    def check(value: str) -> str | None:
        from raysim.sensors.ais_fields import AIS_CHARS

        bad = sorted({c for c in value.upper() if c not in AIS_CHARS})
        if bad:
            return f"characters {''.join(bad)!r} are not in the AIS 6-bit character set"
        if len(value) > limit:
            return f"at most {limit} characters, got {len(value)}"
        return None

    return check


@dataclass(frozen=True, kw_only=True)
class ShipAis:
    enabled: bool = param(True, doc="Transponder on (false = a silent ship)")
    mmsi: int = param(doc="Maritime Mobile Service Identity, 9 digits", check=_mmsi_check)
    ais_class: Literal["A", "B"] = param("A", doc="Transponder class: A (types 1/3 and 5) or B (types 18 and 24)")
    name: str | None = param(None, doc="Vessel name, up to 20 characters", default_doc="the ship's name, upper case",
                             check=_ais_text(20))
    call_sign: str | None = param(None, doc="Call sign, up to 7 characters; null: not available", check=_ais_text(7))
    ship_type: int | None = param(None, doc="ITU ship and cargo type, 0..99", ge=0, le=99,
                                  default_doc="70 (cargo) for class A, 37 (pleasure craft) for class B")
    draught_m: float | None = param(None, doc="Draught, m", ge=0, le=25.5, default_doc="0.06 x length_m, at most 25.5")
    destination: str | None = param(None, doc="Destination, up to 20 characters; null: not available", check=_ais_text(20))
    nav_status: Literal["auto", "under_way", "at_anchor", "moored"] = param(
        "auto", doc="Navigation status; auto: at anchor when anchored, else under way using engine")
    antenna_height_m: float | None = param(None, doc="Transmitting antenna height above the sea, m", gt=0, le=100, check=SIZE_CHECK,
                                           default_doc="the ship's height")
    dropout_probability: float = param(0.0, doc="Chance that a report is lost (intermittent reception)", ge=0, le=1)
    off_periods_s: tuple[tuple[float, float], ...] = param(
        (), doc="Periods [start, end] (s) with the transponder switched off", check=_periods_check)
    position_offset_m: tuple[float, float] = param(
        (0.0, 0.0), doc="Offset [east, north] added to every reported position, m (a spoofed or misconfigured fix)")


@dataclass(frozen=True, kw_only=True)
class Ship:
    name: str = param(doc="Unique name")
    kind: Literal["ship"] = param("ship", doc="Object kind")
    length_m: float = param(30.0, doc="Length overall, m", gt=0, le=500, check=SIZE_CHECK)
    beam_m: float | None = param(None, doc="Beam, m", gt=0, le=80, check=SIZE_CHECK, default_doc="length_m / (3.2 + 0.03 length_m)")
    speed_kn: float = param(0.0, doc="Speed, knots (0 with one waypoint = anchored)", ge=0, le=60)
    waypoints: tuple[LatLon, ...] = param(doc="Waypoints [lat, lon], deg", min_items=1, check=_waypoints_check)
    heading_deg: float | None = param(None, doc="Heading of an anchored ship, compass deg", ge=0, lt=360, default_doc="first leg's course, or 0")
    at_end: Literal["continue", "stop", "loop"] = param("continue", doc="After the last waypoint: keep course, stop, or loop")
    heading_time_constant_s: float | None = param(None, doc="First-order heading response time constant, s", gt=0, le=600, default_doc="0.1 s/m x length_m, clipped to [2, 60] s")
    mesh: Path | None = param(None, doc="Mesh file (body frame, metres); null = generated hull of length_m", check=_MESH_FILE)
    material: str | None = param(None, doc="Material of a mesh file's faces (generated hulls: steel, GRP under 15 m)", default_doc="steel_painted (mesh)")
    ais: ShipAis | None = param(None, doc="AIS transponder; null = none")


@dataclass(frozen=True, kw_only=True)
class Scenario:
    name: str = param("scenario", doc="Scenario name", default_doc="the file name without extension")
    start_time: dt.datetime = param(dt.datetime(2017, 6, 1, 12, tzinfo=dt.timezone.utc), doc="UTC start; stamps PCAP, NMEA and bags")
    duration_s: float = param(300.0, doc="Duration, s", gt=0, le=86_400)
    seed: int = param(0, doc="The one seed of every random stream", ge=0, le=2**63 - 1)
    origin: Origin | None = param(None, doc="Origin of the local frame", default_doc="own ship's start position")
    environment: Environment = param(default_factory=Environment, doc="Weather and sea")
    own_ship: OwnShip = param(default_factory=OwnShip, doc="The own ship carrying the sensors")
    sensors: Sensors = param(default_factory=Sensors, doc="Sensors on the own ship")
    tdm: Tdm = param(default_factory=Tdm, doc="Target detection module settings")
    obstacles: tuple[Obstacle, ...] = param((), doc="Fixed obstacles")
    ships: tuple[Ship, ...] = param((), doc="Other vessels")
    source_file: str = field(default="", compare=False, repr=False, init=False)

    def own_ship_start(self) -> LatLon:
        """[lat, lon] of the own ship at t = 0 (trajectory files are read by raysim.motion)."""
        own = self.own_ship
        if own.route is not None:
            return own.route.waypoints[0]
        if own.position is not None:
            return own.position
        from raysim.trajectory_csv import read_trajectory_csv

        track = read_trajectory_csv(own.trajectory_csv)
        return float(track.lat_deg[0]), float(track.lon_deg[0])


# ---------------------------------------------------------------------------- loading


def load_scenario(path: str | Path, resolve_defaults: bool = True, changes: dict[str, object] | None = None) -> Scenario:
    """Load, validate and (by default) resolve a scenario file.

    Parameters
    ----------
    path : str or Path
    resolve_defaults : bool
        Fill in every default (:func:`resolve`).
    changes : dict, optional
        Values to set before validation, by dotted key path (``environment.sea_state``;
        a number picks a list item: ``ships.0.speed_kn``); missing mappings on the way are
        created. ``raysim batch --vary`` uses this; the result is validated like the file.

    Raises
    ------
    InputError
        For every kind of bad input, naming the file, the key path and the problem.
    """
    path = Path(path)
    data = read_yaml(path)
    if data is None:
        raise InputError(str(path), "(file)", "file holds no scenario (only comments?)")
    if not isinstance(data, dict):
        raise InputError(str(path), "(top level)", "must be a mapping of keys (name, duration_s, own_ship, ...)")
    for key, value in (changes or {}).items():
        set_key_path(data, key, value, str(path))
    ctx = Context(path)
    if "name" not in data:
        data = {"name": path.stem, **data}
    scenario = schema.build(Scenario, data, ctx)
    object.__setattr__(scenario, "source_file", str(path))
    from raysim.scenario_checks import validate

    validate(scenario, ctx)
    return resolve(scenario) if resolve_defaults else scenario


def set_key_path(data: dict, key_path: str, value: object, file: str = "(scenario)") -> None:
    """Set ``value`` at the dotted ``key_path`` of parsed scenario YAML (in place).

    Mappings missing on the way are created; a number indexes a list. Whether the key exists in
    the scenario format is checked when the result is validated (unknown keys are errors there).

    Raises
    ------
    InputError
        When the path runs into a value that is neither a mapping nor a list, or past a list's end.
    """
    parts = key_path.split(".")
    if not key_path or any(not p for p in parts):
        raise InputError(file, key_path or "(key)", "not a dotted key path (like environment.sea_state)")
    node: object = data
    for depth, part in enumerate(parts):
        where = ".".join(parts[: depth + 1])
        last = depth == len(parts) - 1
        if isinstance(node, list):
            if not part.isdigit() or int(part) >= len(node):
                raise InputError(file, where, f"not an item of the list ({len(node)} items, numbered from 0)")
            if last:
                node[int(part)] = value
            else:
                node = node[int(part)]
        elif isinstance(node, dict):
            if last:
                node[part] = value
            else:
                if node.get(part) is None:
                    node[part] = {}
                node = node[part]
        else:
            raise InputError(file, ".".join(parts[:depth]), "holds a single value, not keys to set below it")


# ---------------------------------------------------------------------------- defaults


def heading_time_constant_s(length_m: float) -> float:
    """Default first-order heading time constant: 0.1 s per metre of length, clipped to [2, 60] s.

    An engineering default (unverified): Nomoto time constants of displacement ships are of the order
    of one ship length travelled at service speed; small craft respond in seconds.
    """
    return float(min(60.0, max(2.0, 0.1 * length_m)))


def default_beam_m(length_m: float) -> float:
    """Default beam from length: the generated hulls' rule (:func:`raysim.meshes.default_beam_m`), to 1 cm."""
    from raysim.meshes import default_beam_m as hull_beam_m

    return round(hull_beam_m(length_m), 2)


def _leg_course_deg(waypoints: tuple[LatLon, ...], frame) -> float | None:
    if len(waypoints) < 2:
        return None
    x, y = frame.to_local([w[0] for w in waypoints[:2]], [w[1] for w in waypoints[:2]])
    return float(math.degrees(math.atan2(x[1] - x[0], y[1] - y[0])) % 360.0)


def _resolve_motion(motion: WaveMotion, sea_state: int) -> WaveMotion:
    table = SEA_STATE_MOTION
    period = table["wave_period_s"][sea_state]
    roll_period = 5.0 if sea_state <= 4 else (6.0 if sea_state == 5 else 7.0)
    defaults = dict(
        roll_amplitude_deg=table["roll_amplitude_deg"][sea_state],
        roll_period_s=roll_period,
        pitch_amplitude_deg=table["pitch_amplitude_deg"][sea_state],
        pitch_period_s=4.0,
        heave_amplitude_m=table["heave_amplitude_m"][sea_state],
        heave_period_s=period,
    )
    return dataclasses.replace(motion, **{k: v for k, v in defaults.items() if getattr(motion, k) is None})


def resolve(s: Scenario) -> Scenario:
    """Fill every derived default, so that the result is explicit and re-renders identically."""
    from raysim.geodesy import LocalFrame

    start = s.own_ship_start()
    origin = s.origin or Origin(lat=start[0], lon=start[1])
    frame = LocalFrame(origin.lat, origin.lon)
    own = s.own_ship
    route = own.route
    if route is not None and route.heading_time_constant_s is None:
        route = dataclasses.replace(route, heading_time_constant_s=heading_time_constant_s(own.length_m))
    own = dataclasses.replace(
        own,
        beam_m=own.beam_m if own.beam_m is not None else default_beam_m(own.length_m),
        route=route,
        motion=_resolve_motion(own.motion, s.environment.sea_state),
    )
    obstacles = []
    for o in s.obstacles:
        if o.kind == "iceberg":
            radius = o.radius_m if o.radius_m is not None else 15.0
            o = dataclasses.replace(
                o,
                radius_m=radius,
                height_m=o.height_m if o.height_m is not None else round(0.5 * radius, 3),
                seed=o.seed if o.seed is not None else zlib.crc32(o.name.encode("utf-8")),
            )
        elif o.kind == "mesh" and o.material is None:
            o = dataclasses.replace(o, material="concrete")
        obstacles.append(o)
    ships = []
    for ship in s.ships:
        heading = ship.heading_deg
        if heading is None:
            course = _leg_course_deg(ship.waypoints, frame)
            heading = round(course, 6) if course is not None else 0.0
        ships.append(
            dataclasses.replace(
                ship,
                beam_m=ship.beam_m if ship.beam_m is not None else default_beam_m(ship.length_m),
                material=ship.material if ship.material is not None or ship.mesh is None else "steel_painted",
                heading_deg=heading,
                heading_time_constant_s=ship.heading_time_constant_s
                if ship.heading_time_constant_s is not None
                else heading_time_constant_s(ship.length_m),
            )
        )
    out = dataclasses.replace(s, origin=origin, own_ship=own, obstacles=tuple(obstacles), ships=tuple(ships))
    object.__setattr__(out, "source_file", s.source_file)
    return out


def with_overrides(s: Scenario, duration_s: float | None = None, seed: int | None = None, sensors: tuple[str, ...] | None = None) -> Scenario:
    """The scenario with command-line overrides applied (values already validated by the CLI)."""
    changes: dict = {}
    if duration_s is not None:
        from raysim.limits import time_span_problem

        problem = time_span_problem(s.start_time, float(duration_s), "--duration")
        if problem:
            raise InputError(s.source_file or "scenario", "start_time", problem)
        changes["duration_s"] = float(duration_s)
    if seed is not None:
        changes["seed"] = int(seed)
    if sensors is not None:
        current = s.sensors
        changes["sensors"] = dataclasses.replace(
            current,
            **{f.name: dataclasses.replace(getattr(current, f.name), enabled=f.name in sensors) for f in dataclasses.fields(current)},
        )
    out = dataclasses.replace(s, **changes)
    object.__setattr__(out, "source_file", s.source_file)
    return out


# ---------------------------------------------------------------------------- writing


class _Dumper(yaml.SafeDumper):
    pass


def _represent_list(dumper: yaml.SafeDumper, data: list):
    flow = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in data) and len(data) <= 8
    return dumper.represent_sequence("tag:yaml.org,2002:seq", data, flow_style=flow)


_Dumper.add_representer(list, _represent_list)


def scenario_to_yaml(s: Scenario) -> str:
    """The scenario as YAML text (deterministic; all fields, defaults included)."""
    plain = schema.to_plain(s)
    return yaml.dump(plain, Dumper=_Dumper, sort_keys=False, allow_unicode=True, width=100)


def describe_markdown() -> str:
    """Markdown table of every scenario key, its type, default and meaning."""
    lines = ["| key | type | default | meaning |", "|---|---|---|---|"]
    for key, tp, default, doc in schema.describe(Scenario):
        lines.append(f"| `{key}` | {tp} | {default.replace('|', '/')} | {doc.replace('|', '/')} |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":  # pragma: no cover - documentation helper
    if sys.argv[1:] == ["--doc"]:
        sys.stdout.write(describe_markdown())
