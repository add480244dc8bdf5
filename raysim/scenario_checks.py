"""Checks of a built scenario across fields, which a per-field schema cannot express.

:func:`validate` runs after :func:`raysim.schema.build` in :func:`raysim.scenario.load_scenario`:
one own-ship motion, unique names and MMSIs, known materials, keys that apply to an object's
kind, the run's times within what the outputs can stamp (:mod:`raysim.limits`), the scene's
object count, the trajectory CSV's coverage, every position within
:data:`raysim.limits.MAX_DISTANCE_FROM_ORIGIN_M` of the origin, and nothing on land
(:mod:`raysim.land.checks`). Each failure is one
:class:`raysim.errors.InputError` naming the key path.
"""

from __future__ import annotations

import math

import numpy as np

from raysim import limits
from raysim.errors import InputError
from raysim.limits import MAX_DISTANCE_FROM_ORIGIN_M
from raysim.scenario_format import LatLon, Scenario
from raysim.schema import Context


def validate(s: Scenario, ctx: Context) -> None:
    """Every cross-field check of a built (unresolved) scenario.

    Raises
    ------
    InputError
        The first problem found, naming ``ctx.file`` and the key path.
    """
    problem = limits.time_span_problem(s.start_time, s.duration_s)
    if problem:
        ctx.fail("start_time", problem)
    _check_object_count(s, ctx)
    _check_own_ship(s, ctx)
    names: dict[str, str] = {s.own_ship.name: "own_ship.name"}
    for i, obstacle in enumerate(s.obstacles):
        _check_obstacle(ctx, f"obstacles[{i}]", obstacle, names)
    mmsis: dict[int, str] = {}
    for i, ship in enumerate(s.ships):
        _check_ship(ctx, f"ships[{i}]", ship, names, mmsis)
    _check_distances(s, ctx)
    if s.land:
        from raysim.land.checks import check_land

        check_land(s, ctx, names)


def _check_object_count(s: Scenario, ctx: Context) -> None:
    problem = limits.object_count_problem(1 + len(s.obstacles) + len(s.ships), s.duration_s)
    if problem:
        ctx.fail("obstacles" if len(s.obstacles) >= len(s.ships) else "ships", problem)


def _check_own_ship(s: Scenario, ctx: Context) -> None:
    from raysim import materials

    own = s.own_ship
    given = [k for k in ("route", "trajectory_csv", "position") if getattr(own, k) is not None]
    if len(given) > 1:
        ctx.fail("own_ship", f"give only one of route, trajectory_csv, position (got {', '.join(given)})")
    if not given:
        ctx.fail("own_ship", "needs a route, a trajectory_csv or a position")
    if own.trajectory_csv is not None:
        from raysim.trajectory_csv import read_trajectory_csv

        track = read_trajectory_csv(own.trajectory_csv)
        if track.t_s[-1] < s.duration_s:
            ctx.fail("own_ship.trajectory_csv", f"covers 0..{track.t_s[-1]:g} s but duration_s is {s.duration_s:g}")
    _check_material(ctx, "own_ship.material", own.material, materials)


def _check_obstacle(ctx: Context, where: str, obstacle, names: dict[str, str]) -> None:
    from raysim import materials

    _check_unique(ctx, names, obstacle.name, where + ".name")
    generated_only = {"radius_m", "height_m", "seed"}
    if obstacle.kind != "iceberg":
        for key in sorted(generated_only):
            if getattr(obstacle, key) is not None:
                ctx.fail(f"{where}.{key}", f"only applies to kind iceberg, not {obstacle.kind}")
    if obstacle.kind == "mesh" and obstacle.mesh is None:
        ctx.fail(f"{where}.mesh", "required for kind mesh")
    if obstacle.kind != "mesh":
        for key in ("mesh", "material"):
            if getattr(obstacle, key) is not None:
                ctx.fail(f"{where}.{key}", f"only applies to kind mesh, not {obstacle.kind}")
    if obstacle.material is not None:
        _check_material(ctx, where + ".material", obstacle.material, materials)


def _check_ship(ctx: Context, where: str, ship, names: dict[str, str], mmsis: dict[int, str]) -> None:
    from raysim import materials

    _check_unique(ctx, names, ship.name, where + ".name")
    if ship.material is not None:
        if ship.mesh is None:
            ctx.fail(where + ".material", "only applies to a ship with a mesh file (generated hulls bring their own)")
        _check_material(ctx, where + ".material", ship.material, materials)
    if ship.ais is not None:
        if ship.ais.mmsi in mmsis:
            ctx.fail(where + ".ais.mmsi", f"MMSI {ship.ais.mmsi} is already used by {mmsis[ship.ais.mmsi]}")
        mmsis[ship.ais.mmsi] = where
    if len(ship.waypoints) == 1 and ship.speed_kn > 0:
        ctx.fail(where + ".speed_kn", "a ship with one waypoint is anchored: speed_kn must be 0 (add a waypoint to move)")


def _check_unique(ctx: Context, names: dict[str, str], name: str, where: str) -> None:
    if name in names:
        ctx.fail(where, f"name {name!r} is already used by {names[name].rsplit('.', 1)[0]}")
    names[name] = where


def _check_material(ctx: Context, where: str, name: str, materials) -> None:
    try:
        materials.material_index(name)
    except KeyError:
        ctx.fail(where, f"unknown material {name!r} (known: {', '.join(m.name for m in materials.MATERIALS)})")


def _too_far(distance_m: float) -> str:
    return (f"is {distance_m / 1000:.1f} km from the origin; a scenario must stay within "
            f"{MAX_DISTANCE_FROM_ORIGIN_M / 1000:g} km")


def _check_distances(s: Scenario, ctx: Context) -> None:
    from raysim.geodesy import LocalFrame

    origin = (s.origin.lat, s.origin.lon) if s.origin else s.own_ship_start()
    frame = LocalFrame(*origin)
    places: list[tuple[str, LatLon]] = []
    if s.own_ship.route:
        places += [(f"own_ship.route.waypoints[{i}]", wp) for i, wp in enumerate(s.own_ship.route.waypoints)]
    if s.own_ship.position:
        places.append(("own_ship.position", s.own_ship.position))
    places += [(f"obstacles[{i}].position", o.position) for i, o in enumerate(s.obstacles)]
    for i, ship in enumerate(s.ships):
        places += [(f"ships[{i}].waypoints[{j}]", wp) for j, wp in enumerate(ship.waypoints)]
    if s.own_ship.trajectory_csv is not None:
        _check_csv_distances(s, origin)
    if not places:
        return
    lat = [p[1][0] for p in places]
    lon = [p[1][1] for p in places]
    x, y = frame.to_local(lat, lon)
    for (where, _), xi, yi in zip(places, x, y):
        distance = math.hypot(xi, yi)
        if not distance <= MAX_DISTANCE_FROM_ORIGIN_M:
            ctx.fail(where, _too_far(distance))


def _check_csv_distances(s: Scenario, origin: LatLon) -> None:
    """Every sample of the own ship's trajectory CSV within reach of the origin (great-circle distance)."""
    from raysim.trajectory_csv import read_trajectory_csv

    track = read_trajectory_csv(s.own_ship.trajectory_csv)
    lat0, lon0 = np.radians(origin[0]), np.radians(origin[1])
    lat, lon = np.radians(track.lat_deg), np.radians(track.lon_deg)
    hav = np.sin((lat - lat0) / 2.0) ** 2 + np.cos(lat0) * np.cos(lat) * np.sin((lon - lon0) / 2.0) ** 2
    distance_m = 2.0 * limits.EARTH_RADIUS_M * np.arcsin(np.sqrt(np.clip(hav, 0.0, 1.0)))
    far = distance_m > MAX_DISTANCE_FROM_ORIGIN_M
    if far.any():
        k = int(np.argmax(far))
        line = f"line {track.line[k]}" if track.line is not None else f"sample {k}"
        raise InputError(str(s.own_ship.trajectory_csv), line, _too_far(float(distance_m[k])))
