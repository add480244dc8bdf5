"""Scenario files: the native YAML format of docs/scenario.md, loaded strictly into typed objects.

``load_scenario(path)`` parses with :func:`raysim.yaml_loader.read_yaml` (safe constructors
only; keys given twice, alias bombs and deep nesting refused), validates every key
(unknown keys, wrong types, NaN/inf, float32-collapsing and out-of-range values are errors
naming the key path), checks that referenced files are regular files
(:mod:`raysim.input_files`) against the format's classes (:mod:`raysim.scenario_format`), the cross-field rules (:mod:`raysim.scenario_checks`, with the
limits of :mod:`raysim.limits`), and returns a :class:`Scenario` whose derived defaults are
filled in (:func:`resolve`). ``dump_scenario`` writes
the resolved scenario back as YAML (the recording's ``scenario.yaml``).

Every field and its default is listed in docs/scenario.md (generated from this
module by ``python -m raysim.scenario --doc``; a test keeps them in sync).
"""

from __future__ import annotations

import dataclasses
import math
import sys
import zlib
from pathlib import Path

import yaml

from raysim import schema
from raysim.errors import InputError
from raysim.limits import MAX_DISTANCE_FROM_ORIGIN_M  # noqa: F401 (importable here as before)
from raysim.scenario_checks import validate
from raysim.scenario_format import (  # noqa: F401 (the format's classes, importable here as before)
    Ais,
    AisNoise,
    Environment,
    LatLon,
    Lidar,
    Mount,
    Nav,
    Obstacle,
    Origin,
    OwnShip,
    Radar,
    Route,
    Scenario,
    Sensors,
    Ship,
    ShipAis,
    Tdm,
    WaveMotion,
)
from raysim.schema import Context
from raysim.sea import DOUGLAS_WAVE_HEIGHT_M  # noqa: F401 (sea physics: raysim.sea; importable here as before)
from raysim.yaml_loader import read_yaml  # noqa: F401 (raysim.hilsim reads the thesis's files with it)

#: Own-ship wave motion defaults per Douglas sea state 0..6 for a ~11 m craft
#: (engineering defaults, unverified; override with own_ship.motion).
#: Heave amplitude about 0.35 x the significant wave height mid-band.
SEA_STATE_MOTION = {
    "roll_amplitude_deg": (0.0, 0.5, 1.5, 3.0, 5.0, 8.0, 12.0),
    "pitch_amplitude_deg": (0.0, 0.3, 0.8, 1.5, 2.5, 4.0, 6.0),
    "heave_amplitude_m": (0.0, 0.02, 0.1, 0.3, 0.65, 1.1, 1.75),
    "wave_period_s": (2.0, 2.0, 3.0, 4.0, 5.0, 6.5, 8.0),
}


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
