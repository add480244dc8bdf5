"""Scenario checks that need the land: names, routes and positions against the land polygons.

:func:`check_land` runs from :func:`raysim.scenario_checks.validate`. Routes are checked leg by leg
as straight lines in lon/lat (over the few kilometres of a leg the difference from the local
plane is centimetres), positions as points; the land polygons come from their GeoJSON files
(:func:`raysim.land.geojson.read_land_file`, whose own errors name the GeoJSON file).
"""

from __future__ import annotations

from shapely import STRtree
from shapely.geometry import LineString, Point

from raysim.land.geojson import LandPolygon, read_land_file
from raysim.scenario_format import LatLon, Scenario
from raysim.schema import Context


def land_polygons(s: Scenario) -> list[tuple[int, LandPolygon]]:
    """Every land polygon of the scenario with the index of its ``land`` entry, in file order.

    Raises
    ------
    InputError
        A GeoJSON file's own problem (:func:`read_land_file`).
    """
    out = []
    for i, entry in enumerate(s.land):
        for polygon in read_land_file(entry.file, entry.height_m, entry.material):
            out.append((i, polygon))
    return out


def check_land(s: Scenario, ctx: Context, names: dict[str, str]) -> None:
    """Unique land names; no route leg, start or object position on land.

    Parameters
    ----------
    s : Scenario
        Built (unresolved) scenario.
    ctx : Context
        Names the scenario file in errors.
    names : dict
        Names already taken (name -> key path), extended with the land entries'.
    """
    for i, entry in enumerate(s.land):
        if entry.name in names:
            ctx.fail(f"land[{i}].name", f"name {entry.name!r} is already used by {names[entry.name].rsplit('.', 1)[0]}")
        names[entry.name] = f"land[{i}].name"
    polygons = land_polygons(s)
    if not polygons:
        return
    tree = STRtree([p.polygon for _, p in polygons])

    def on_land(geometry) -> str | None:
        for k in tree.query(geometry, predicate="intersects"):
            index, polygon = polygons[int(k)]
            entry = s.land[index]
            return f"{entry.name!r} ({entry.file.name} {polygon.where or 'polygon'})"
        return None

    for where, place in _points(s):
        hit = on_land(Point(place[1], place[0]))
        if hit:
            ctx.fail(where, f"is on land {hit}")
    for where, waypoints in _routes(s):
        for j in range(len(waypoints) - 1):
            leg = LineString([(waypoints[j][1], waypoints[j][0]), (waypoints[j + 1][1], waypoints[j + 1][0])])
            hit = on_land(leg)
            if hit:
                closing = j + 2 == len(waypoints) and len(waypoints) > 2 and waypoints[-1] == waypoints[0]
                k = 0 if closing else j + 1
                what = "sample" if where.endswith("csv") else "waypoint"
                ctx.fail(where, f"the leg from {what} {j} to {k} crosses land {hit}")


def _points(s: Scenario) -> list[tuple[str, LatLon]]:
    """Key paths and [lat, lon] of the own ship's start, the obstacles and every ship waypoint."""
    points: list[tuple[str, LatLon]] = []
    if s.own_ship.position is not None:
        points.append(("own_ship.position", s.own_ship.position))
    if s.own_ship.route is not None:
        points += [(f"own_ship.route.waypoints[{i}]", wp) for i, wp in enumerate(s.own_ship.route.waypoints)]
    points += [(f"obstacles[{i}].position", o.position) for i, o in enumerate(s.obstacles)]
    for i, ship in enumerate(s.ships):
        points += [(f"ships[{i}].waypoints[{j}]", wp) for j, wp in enumerate(ship.waypoints)]
    return points


def _routes(s: Scenario) -> list[tuple[str, tuple[LatLon, ...]]]:
    """Key paths and waypoints of the own ship's route (or trajectory file) and every ship's route.

    A route that loops gets its closing leg back to the first waypoint; the course a ship keeps after its last
    waypoint (``at_end: continue``) is not checked.
    """
    def legs(route, at_end: str) -> tuple[LatLon, ...]:
        return tuple(route) + (route[0],) if at_end == "loop" and len(route) > 2 else tuple(route)

    routes = []
    own = s.own_ship
    if own.route is not None:
        routes.append(("own_ship.route.waypoints", legs(own.route.waypoints, own.route.at_end)))
    if own.trajectory_csv is not None:
        from raysim.trajectory_csv import read_trajectory_csv

        track = read_trajectory_csv(own.trajectory_csv)
        routes.append(("own_ship.trajectory_csv", tuple(zip(track.lat_deg.tolist(), track.lon_deg.tolist()))))
    routes += [(f"ships[{i}].waypoints", legs(ship.waypoints, ship.at_end)) for i, ship in enumerate(s.ships)]
    return routes


__all__ = ["check_land", "land_polygons"]
