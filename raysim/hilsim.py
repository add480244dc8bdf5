"""Import the 2017 HIL simulator's configuration files (thesis ch. 6.5 and appendix B).

Three files: obstacles (``fixed_obstacles`` and ``ships`` maps of strings such as
``RADIUS=15 COORD=10,470952/59,436573`` -- lon/lat with decimal commas -- and
``LENGTH=30 SpeedInKnots=1 WP=lon/lat WP=...``), sensors (ranges, TDM rate and
the AIS/radar/LiDAR noise parameters) and, optionally, dynamics (start position,
wind, current, waves, sensor rates). The result is a native scenario (a dict
ready for YAML, plus comment lines for what has no native equivalent).

Mapping (docs/scenario.md, "Importing the thesis's files"):

- icebergs -> ``obstacles`` of kind iceberg with their radius; ships -> ``ships``
  with AIS transponders (MMSI 2570000NN in file order: the thesis gives none);
- ``AIS_*`` noise parameters -> ``sensors.ais.noise`` (same names, lower case,
  without the prefix); ``AIS_range_m``, ``radar_range_m``, ``lidar_range_m``,
  ``TDM_update_rate_Hz`` -> their sensor keys;
- the radar and LiDAR noise parameters and ``error_pr_distance_gain`` described the
  thesis's *faked* TDM output; raysim renders raw data whose errors follow from
  geometry and physics, so they are kept as comments only;
- dynamics: start position -> origin and own-ship start; wind -> environment;
  ``wave_height`` (m, taken as significant height) -> Douglas sea state;
  ``gps_frequency`` -> ``sensors.nav.rate_hz``; current, ``dt`` and the other
  rates are kept as comments.
"""

from __future__ import annotations

import re
from pathlib import Path

import yaml

from raysim.errors import InputError
from raysim.scenario import DOUGLAS_WAVE_HEIGHT_M, read_yaml

MMSI_BASE = 257_000_000  # MID 257 = Norway, where the thesis's scenario sails

SENSOR_RANGE_KEYS = {
    "AIS_range_m": ("ais", "range_m"),
    "radar_range_m": ("radar", "range_m"),
    "lidar_range_m": ("lidar", "range_max_m"),
}
AIS_NOISE_FIELDS = [
    f"{q}_{kind}"
    for kind in ("measure_variance", "bias_variance", "bias_time_constant")
    for q in ("position", "COG", "track", "ROT", "SOG")
]
_AIS_UNITS = {
    "position_measure_variance": "m2", "COG_measure_variance": "deg2", "track_measure_variance": "deg2",
    "ROT_measure_variance": "deg2_pr_min2", "SOG_measure_variance": "knots2",
    "position_bias_variance": "m2", "COG_bias_variance": "deg2", "track_bias_variance": "deg2",
    "ROT_bias_variance": "deg2_pr_min2", "SOG_bias_variance": "knots2",
}
COMMENT_ONLY_SENSOR_KEYS = (
    "error_pr_distance_gain",
    "radar_position_measure_variance_m2", "radar_radius_measure_variance_m2", "radar_position_bias_variance_m2",
    "radar_radius_bias_variance_m2", "radar_position_bias_time_constant_sec", "radar_radius_bias_time_constant_sec",
    "lidar_position_measure_variance_m2", "lidar_radius_measure_variance_m2", "lidar_position_bias_variance_m2",
    "lidar_radius_bias_variance_m2", "lidar_position_bias_time_constant_sec", "lidar_radius_bias_time_constant_sec",
)
DYNAMICS_KEYS = {
    "wind_speed", "wind_direction", "current_speed", "current_direction", "wave_height", "wave_direction", "dt",
    "gps_frequency", "mru_frequency", "imu_frequency", "speed_sensor_frequency", "wind_sensor_frequency",
    "start_latitude", "start_longitude",
}


def _ais_noise_key(field: str) -> str:
    """Thesis name without ``AIS_`` -> native key, e.g. COG_bias_variance -> cog_bias_variance_deg2."""
    unit = "sec" if field.endswith("time_constant") else _AIS_UNITS[field]
    return f"{field.lower()}_{unit}"


def _load(path: Path) -> dict:
    data = read_yaml(Path(path))
    if not isinstance(data, dict):
        raise InputError(str(path), "(top level)", "must be a mapping of keys to values")
    return data


def _number(file: str, where: str, text: str) -> float:
    try:
        value = float(text.replace(",", "."))
    except ValueError:
        raise InputError(file, where, f"not a number: {text!r}") from None
    if value != value or value in (float("inf"), float("-inf")):
        raise InputError(file, where, f"must be finite, got {text!r}")
    return value


def _coord(file: str, where: str, text: str) -> list[float]:
    """``10,470952/59,436573`` (lon/lat, decimal commas) -> [lat, lon]."""
    parts = text.split("/")
    if len(parts) != 2:
        raise InputError(file, where, f"a coordinate is LON/LAT with decimal commas, got {text!r}")
    lon, lat = (_number(file, where, p) for p in parts)
    if not (-90 <= lat <= 90 and -180 <= lon <= 180):
        raise InputError(file, where, f"coordinate out of range (lon {lon:g}, lat {lat:g})")
    return [round(lat, 9), round(lon, 9)]


_TOKEN = re.compile(r"^([A-Za-z]+)=(\S+)$")


def _tokens(file: str, where: str, text: object, allowed: set[str]) -> list[tuple[str, str]]:
    if not isinstance(text, str):
        raise InputError(file, where, f"must be a string such as 'RADIUS=15 COORD=10,47/59,43', got {text!r}")
    out = []
    for token in text.split():
        match = _TOKEN.match(token)
        if not match:
            raise InputError(file, where, f"cannot read {token!r} (expected KEY=VALUE)")
        if match.group(1) not in allowed:
            raise InputError(file, where, f"unknown field {match.group(1)!r} (known: {', '.join(sorted(allowed))})")
        out.append((match.group(1), match.group(2)))
    return out


def import_hilsim(obstacles_path: Path, sensors_path: Path, dynamics_path: Path | None = None,
                  name: str = "busy_open_sea", route: list[list[float]] | None = None, speed_kn: float = 8.0,
                  duration_s: float = 300.0) -> tuple[dict, list[str]]:
    """Convert the thesis's files into a native scenario.

    Parameters
    ----------
    obstacles_path, sensors_path, dynamics_path : Path
        The three configuration files (dynamics optional).
    name : str
        Scenario name.
    route : list of [lat, lon], optional
        Own-ship waypoints (the thesis drove Odin from logged thrust, which these files
        do not hold); default: the own ship lies still at the start position.
    speed_kn, duration_s : float
        Own-ship speed on the route, and the scenario duration.

    Returns
    -------
    scenario : dict
        Native scenario, ready for ``yaml`` and :func:`raysim.scenario.load_scenario`.
    comments : list of str
        Lines about parameters that have no native equivalent.
    """
    obstacles_file = str(obstacles_path)
    obstacles_data = _load(obstacles_path)
    sensors_data = _load(sensors_path)
    dynamics_data = _load(dynamics_path) if dynamics_path is not None else {}
    for key in obstacles_data:
        if key not in ("fixed_obstacles", "ships"):
            raise InputError(obstacles_file, str(key), "unknown key (allowed: fixed_obstacles, ships)")
    comments: list[str] = []
    obstacles = _obstacles(obstacles_file, obstacles_data.get("fixed_obstacles") or {})
    ships = _ships(obstacles_file, obstacles_data.get("ships") or {})
    sensors, tdm = _sensors(str(sensors_path), sensors_data, comments)

    scenario: dict = {"name": name, "start_time": "2017-06-01T12:00:00Z", "duration_s": float(duration_s), "seed": 7}
    environment: dict = {}
    start = None
    if dynamics_path is not None:
        start = _dynamics(str(dynamics_path), dynamics_data, scenario, environment, sensors, comments)
    if environment:
        scenario["environment"] = environment
    scenario["own_ship"] = _own_ship(obstacles_file, route, start, speed_kn)
    scenario["sensors"] = {k: v for k, v in sensors.items() if v and v != {"noise": {}}}
    if tdm:
        scenario["tdm"] = tdm
    scenario["obstacles"] = obstacles
    scenario["ships"] = ships
    return scenario, comments


def _obstacles(obstacles_file: str, fixed: dict) -> list[dict]:
    """The thesis's fixed obstacles (``RADIUS=``, ``COORD=``) as native icebergs."""
    obstacles = []
    for label, text in fixed.items():
        where = f"fixed_obstacles.{label}"
        fields = dict(_tokens(obstacles_file, where, text, {"RADIUS", "COORD"}))
        if "COORD" not in fields:
            raise InputError(obstacles_file, where, "missing COORD=")
        radius = _number(obstacles_file, where, fields.get("RADIUS", "15"))
        if radius <= 0:
            raise InputError(obstacles_file, where, f"RADIUS must be > 0, got {radius:g}")
        obstacles.append({"name": str(label), "kind": "iceberg", "position": _coord(obstacles_file, where, fields["COORD"]),
                          "radius_m": radius})
    return obstacles


def _ships(obstacles_file: str, entries: dict) -> list[dict]:
    """The thesis's ships (``LENGTH=``, ``SpeedInKnots=``, ``WP=``...) as native ships with AIS on."""
    ships = []
    for i, (label, text) in enumerate(entries.items()):
        where = f"ships.{label}"
        tokens = _tokens(obstacles_file, where, text, {"LENGTH", "SpeedInKnots", "WP"})
        fields = dict(tokens)
        waypoints = [_coord(obstacles_file, where, v) for k, v in tokens if k == "WP"]
        if not waypoints:
            raise InputError(obstacles_file, where, "needs at least one WP=")
        length = _number(obstacles_file, where, fields.get("LENGTH", "30"))
        speed = _number(obstacles_file, where, fields.get("SpeedInKnots", "0"))
        if length <= 0 or speed < 0:
            raise InputError(obstacles_file, where, "LENGTH must be > 0 and SpeedInKnots >= 0")
        ships.append({"name": str(label), "kind": "ship", "length_m": length, "speed_kn": speed, "waypoints": waypoints,
                      "ais": {"enabled": True, "mmsi": MMSI_BASE + i + 1}})
    return ships


def _sensors(sensors_file: str, sensors_data: dict, comments: list[str]) -> tuple[dict, dict]:
    """Native ``sensors`` and ``tdm`` sections from the thesis's sensor file; its faked-TDM noise goes to comments."""
    sensors: dict = {"lidar": {}, "radar": {}, "ais": {"noise": {}}, "nav": {}}
    tdm: dict = {}
    noise_keys = {f"AIS_{f}_{'sec' if f.endswith('time_constant') else _AIS_UNITS[f]}": _ais_noise_key(f) for f in AIS_NOISE_FIELDS}
    thesis_fake = []
    for key, value in sensors_data.items():
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise InputError(sensors_file, str(key), f"must be a number, got {value!r}")
        if key in SENSOR_RANGE_KEYS:
            sensor, native = SENSOR_RANGE_KEYS[key]
            sensors[sensor][native] = float(value)
        elif key == "TDM_update_rate_Hz":
            tdm["update_rate_hz"] = float(value)
        elif key in noise_keys:
            sensors["ais"]["noise"][noise_keys[key]] = float(value)
        elif key in COMMENT_ONLY_SENSOR_KEYS:
            thesis_fake.append(f"{key}: {value}")
        else:
            raise InputError(sensors_file, str(key), "unknown key of the thesis's sensor file")
    if thesis_fake:
        comments.append("The thesis's faked-TDM radar/LiDAR noise (raysim derives these errors from physics):")
        comments.extend("  " + line for line in thesis_fake)
    return sensors, tdm


def _dynamics(dyn_file: str, dynamics_data: dict, scenario: dict, environment: dict, sensors: dict,
              comments: list[str]) -> list[float] | None:
    """The thesis's dynamics file into ``scenario`` (origin), ``environment`` and ``sensors``; returns the start position."""
    start = None
    for key, value in dynamics_data.items():
        if key not in DYNAMICS_KEYS:
            raise InputError(dyn_file, str(key), "unknown key of the thesis's dynamics file")
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise InputError(dyn_file, str(key), f"must be a number, got {value!r}")
    if "start_latitude" in dynamics_data and "start_longitude" in dynamics_data:
        start = [float(dynamics_data["start_latitude"]), float(dynamics_data["start_longitude"])]
        if not (-90 <= start[0] <= 90 and -180 <= start[1] <= 180):
            raise InputError(dyn_file, "start_latitude", "start position out of range")
        scenario["origin"] = {"lat": start[0], "lon": start[1]}
    if "wave_height" in dynamics_data:
        height = float(dynamics_data["wave_height"])
        environment["sea_state"] = next((i for i, top in enumerate(DOUGLAS_WAVE_HEIGHT_M) if height <= top), 6)
    if "wind_speed" in dynamics_data:
        environment["wind_speed_mps"] = float(dynamics_data["wind_speed"])
    if "wind_direction" in dynamics_data:
        environment["wind_from_deg"] = float(dynamics_data["wind_direction"]) % 360.0
    if "gps_frequency" in dynamics_data:
        sensors["nav"]["rate_hz"] = float(dynamics_data["gps_frequency"])
    rest = [f"{k}: {dynamics_data[k]}" for k in ("current_speed", "current_direction", "wave_direction", "dt",
                                                  "mru_frequency", "imu_frequency", "speed_sensor_frequency",
                                                  "wind_sensor_frequency") if k in dynamics_data]
    if rest:
        comments.append("The thesis's dynamics settings without a native key (no currents in raysim yet):")
        comments.extend("  " + line for line in rest)
    return start


def _own_ship(obstacles_file: str, route: list[list[float]] | None, start: list[float] | None,
              speed_kn: float) -> dict:
    """Odin on the given route (starting at the thesis's start position), or lying still at the start."""
    own: dict = {"name": "odin", "length_m": 10.9, "beam_m": 3.5}
    if route:
        waypoints = [[float(a), float(b)] for a, b in route]
        if start is not None:
            # the route starts at the thesis's start position (a first point within ~1 m of it is replaced)
            if abs(waypoints[0][0] - start[0]) < 1e-5 and abs(waypoints[0][1] - start[1]) < 2e-5:
                waypoints[0] = start
            else:
                waypoints.insert(0, start)
        own["route"] = {"speed_kn": float(speed_kn), "waypoints": waypoints}
    elif start is not None:
        own["position"] = start
        own["heading_deg"] = 0.0
    else:
        raise InputError(obstacles_file, "(own ship)", "no start position: give the dynamics file or a route")
    return own


def scenario_text(scenario: dict, comments: list[str], header: list[str]) -> str:
    """YAML text of an imported scenario with header and comment lines."""
    from raysim.scenario import _Dumper

    body = yaml.dump(scenario, Dumper=_Dumper, sort_keys=False, width=120)
    lines = ["# " + h for h in header] + ["# " + c for c in comments]
    return "\n".join(lines) + ("\n" if lines else "") + body
