"""Hulls that pass through one another: found at the closest approach, only when certain, warned of by render."""

from __future__ import annotations

import pytest
import yaml

from raysim.render import _warn_of_overlaps
from raysim.scenario import load_scenario
from raysim.world import World
from raysim.world_checks import hull_overlaps

from .helpers import ORIGIN, latlon

KN = 1852.0 / 3600.0


def _world(tmp_path, ships, obstacles=(), duration_s=120.0) -> World:
    data = {
        "name": "overlap_test", "duration_s": duration_s, "seed": 1,
        "origin": {"lat": ORIGIN[0], "lon": ORIGIN[1]},
        "own_ship": {"position": latlon(0, -2000), "heading_deg": 0},
        "sensors": {},
        "obstacles": list(obstacles),
        "ships": list(ships),
    }
    path = tmp_path / "overlap.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return World(load_scenario(path))


def test_a_boat_sailing_through_an_anchored_ship_is_found_at_its_closest_approach(tmp_path):
    # An 8 m boat (beam 8/6 m by default) at 10 kn eastward along y = 0 passes the centre of a
    # 120 m ship anchored at x = 300 m: at t = 300 / (10 kn) = 58.3 s, 0 m apart.
    ships = [{"name": "tanker", "length_m": 120, "beam_m": 18, "waypoints": [latlon(300, 0)], "heading_deg": 0},
             {"name": "boat", "length_m": 8, "beam_m": 2, "speed_kn": 10,
              "waypoints": [latlon(0, 0), latlon(2000, 0)], "heading_deg": 90}]
    found = hull_overlaps(_world(tmp_path, ships))
    assert len(found) == 1
    (o,) = found
    assert (o.where_a, o.where_b) == ("ships[0] (tanker)", "ships[1] (boat)")
    assert o.t_s == pytest.approx(300.0 / (10 * KN), abs=0.5)
    assert o.distance_m < 10 * KN * 0.5  # within half a step of travel
    assert o.allowed_m == pytest.approx(0.5 * 18 + 0.5 * 2)


@pytest.mark.parametrize("offset_m, overlaps", [(9.9, True), (10.2, False), (40.0, False)])
def test_only_centres_closer_than_the_inscribed_radii_count(tmp_path, offset_m, overlaps):
    # The boat passes `offset_m` north of the tanker's centre: 9 + 1 = 10 m is the certain-overlap limit.
    ships = [{"name": "tanker", "length_m": 120, "beam_m": 18, "waypoints": [latlon(300, 0)], "heading_deg": 90},
             {"name": "boat", "length_m": 8, "beam_m": 2, "speed_kn": 4,
              "waypoints": [latlon(0, offset_m), latlon(2000, offset_m)], "heading_deg": 90}]
    found = hull_overlaps(_world(tmp_path, ships, duration_s=200.0))
    assert bool(found) is overlaps
    if found:
        assert found[0].distance_m == pytest.approx(offset_m, abs=0.05)


def test_still_bodies_placed_on_one_another_and_apart(tmp_path):
    obstacles = [{"name": "berg", "kind": "iceberg", "position": latlon(0, 500), "radius_m": 10, "height_m": 5},
                 {"name": "buoy", "kind": "buoy", "position": latlon(3, 500)},
                 {"name": "far_buoy", "kind": "buoy", "position": latlon(300, 500)}]
    found = hull_overlaps(_world(tmp_path, [], obstacles, duration_s=5.0))
    assert [(o.where_a, o.where_b) for o in found] == [("obstacles[0] (berg)", "obstacles[1] (buoy)")]
    assert found[0].distance_m < found[0].allowed_m  # the berg's centre is its above-water box's, off its origin


def test_render_warns_in_one_line_per_pair(tmp_path, capsys):
    ships = [{"name": "tanker", "length_m": 120, "beam_m": 18, "waypoints": [latlon(300, 0)], "heading_deg": 0},
             {"name": "boat", "length_m": 8, "beam_m": 2, "speed_kn": 10,
              "waypoints": [latlon(0, 0), latlon(2000, 0)], "heading_deg": 90}]
    _warn_of_overlaps(_world(tmp_path, ships))
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1
    assert err[0].startswith("warning: ")
    assert "overlap.yaml: ships[0] (tanker) and ships[1] (boat): hulls overlap" in err[0]


def test_the_shipped_scenarios_have_no_hulls_through_one_another():
    from pathlib import Path

    folder = Path(__file__).resolve().parents[2] / "scenarios"
    for path in sorted(folder.glob("*.yaml")):
        assert hull_overlaps(World(load_scenario(path))) == [], path.name
