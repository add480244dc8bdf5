"""The scenario format: every key of a scenario file as a frozen dataclass field.

Each field gives its type, default, bounds and per-field check (:func:`raysim.schema.param`);
:func:`raysim.schema.build` reads YAML into these classes. Checks across fields are in
:mod:`raysim.scenario_checks`, loading and derived defaults in :mod:`raysim.scenario`, which
imports every name of this module. docs/scenario.md lists every key (``python -m raysim.scenario --doc``).
"""

from __future__ import annotations

import dataclasses
import datetime as dt
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

from raysim.input_files import MAX_CSV_FILE_BYTES, MAX_LAND_FILE_BYTES, MAX_MESH_FILE_BYTES, path_check
from raysim.limits import RESOLVE_CHECK, SIZE_CHECK
from raysim.schema import param

#: A position [lat, lon], degrees.
LatLon = tuple[float, float]


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
_LAND_FILE = path_check("GeoJSON file", MAX_LAND_FILE_BYTES)


@dataclass(frozen=True, kw_only=True)
class Origin:
    lat: float = param(doc="Latitude of the local frame's origin, deg", ge=-90, le=90)
    lon: float = param(doc="Longitude of the local frame's origin, deg", ge=-180, le=180)


@dataclass(frozen=True, kw_only=True)
class RainCell:
    """A convective rain cell: an EXCELL exponential profile ``R(r) = rate_mm_per_h exp(-r / radius_m)``
    (Capsoni et al. 1987), drifting with the wind (docs/radar.md section 4)."""

    position: LatLon = param(doc="Centre [lat, lon] of the cell at t = 0, deg", check=_lat_lon_check)
    radius_m: float = param(2000.0, doc="EXCELL 1/e radius r0 of the rate profile, m", gt=0, le=50_000, check=SIZE_CHECK)
    rate_mm_per_h: float = param(20.0, doc="Peak rain rate at the centre (added to rain_mm_per_h), mm/h", gt=0, le=300)


@dataclass(frozen=True, kw_only=True)
class Environment:
    sea_state: int = param(2, doc="Douglas sea state 0..6: sea clutter, foam, waves, own-ship motion", ge=0, le=6)
    wind_speed_mps: float = param(5.0, doc="True wind speed, m/s", ge=0, le=70)
    wind_from_deg: float = param(0.0, doc="Direction the wind blows from, compass deg", ge=0, lt=360)
    rain_mm_per_h: float = param(0.0, doc="Uniform (stratiform) background rain rate everywhere, mm/h (radar attenuation and "
                                 "clutter, LiDAR attenuation)", ge=0, le=300)
    rain_cells: tuple[RainCell, ...] = param(
        (), doc="Convective rain cells (radar): EXCELL exponential profiles added to rain_mm_per_h, drifting with "
        "the wind at wind_speed_mps towards wind_from_deg + 180")
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
class Interferer:
    """Another radar nearby whose pulses our receiver picks up (docs/radar.md, "Interference")."""

    position: LatLon = param(doc="Position [lat, lon] of the other radar, deg", check=_lat_lon_check)
    prf_hz: float = param(1000.0, doc="Its pulse repetition frequency, Hz (marine sets: about 400..4000)", ge=100, le=10_000)
    rpm: float = param(24.0, doc="Its antenna rotation, revolutions per minute", gt=0, le=120)
    level_db: float = param(
        60.0, doc="Received level of its pulses over our noise when both main beams point at each other, dB",
        ge=0, le=150)
    beam_az_deg: float = param(1.9, doc="Its horizontal -3 dB beam width, deg (a 4 ft open array: 1.9)", gt=0, le=45)
    pulse_length_us: float = param(0.08, doc="Its pulse length, us (short-range pulses: 0.05..0.1)", gt=0, le=50)
    azimuth0_deg: float = param(0.0, doc="Its antenna azimuth at t = 0, compass deg", ge=0, lt=360)


@dataclass(frozen=True, kw_only=True)
class Radar:
    enabled: bool = param(True, doc="Render this sensor")
    model: Literal["broadband-4g", "broadband-3g", "magnetron"] = param(
        "broadband-4g", doc="Radar model: broadband-4g / broadband-3g (Simrad/Navico Broadband class FMCW: Hann-windowed "
        "FFT range sidelobes) or magnetron (a pulse set: pulse length by range scale); sets the receiver's range "
        "response and saturation (docs/radar.md section 5)")
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
    sidelobe_db: float = param(
        -25.0, doc="One-way near-in sidelobe level of the horizontal antenna pattern, dB (Taylor taper; far sidelobes "
        "fall below it)", ge=-45, le=-13)
    resolve_m: float = param(
        6.0, doc="Ray spacing across the beam at the range scale (or the horizon if nearer), m", gt=0, le=100,
        check=RESOLVE_CHECK)
    interference: tuple[Interferer, ...] = param(
        (), doc="Other radars whose pulses show as dotted spiral arcs; empty = no interference")
    interference_rejection: Literal["off", "low", "medium", "high"] = param(
        "off", doc="Interference rejection (sweep-to-sweep correlation of the video): off, low (echo on either "
        "neighbouring spoke within 1 sample), medium (on both within 1 sample), high (on both at the same sample)")


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


@dataclass(frozen=True, kw_only=True)
class Land:
    name: str = param(doc="Unique name among all objects")
    file: Path = param(doc="GeoJSON file (RFC 7946) of Polygon/MultiPolygon land in WGS84 lon/lat, holes allowed, "
                       "relative to the scenario file; a feature's height_m, material and slope_deg properties "
                       "override this entry's (docs/land.md)", check=_LAND_FILE)
    height_m: float = param(10.0, doc="Top height above the sea where a feature has no height_m property, m",
                            gt=0, le=2000, check=SIZE_CHECK)
    material: Literal["rock", "vegetation", "sand", "concrete"] = param(
        "rock", doc="Material where a feature has no material property")
    slope_deg: float | None = param(None, doc="Slope of the shore faces, deg from the horizontal (beaches, hills); "
                                    "null = vertical", gt=0, le=90)


def _periods_check(value) -> str | None:
    for i, (start, end) in enumerate(value):
        if not start < end:
            return f"period {i}: start {start} must be before end {end}"
    return None


def _ais_text(limit: int):
    """Check of an AIS text field: the 6-bit character set and at most ``limit`` characters."""

    def check(value: str) -> str | None:
        from raysim.ais_fields import AIS_CHARS

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
    reference_point_m: tuple[float, float] | None = param(
        None, doc="Where the GNSS antenna whose position is reported stands: [from the bow, from the port side], m "
                  "(ITU-R M.1371-5 dimensions A and C; at most the ship's length and beam)", ge=0, le=500,
        default_doc="amidships on the centre line")


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
    land: tuple[Land, ...] = param((), doc="Land: coasts, islands, quays and piers from GeoJSON polygons (docs/land.md)")
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
