"""raysim.world: objects, truth ids, dimensions and motions of a tiny scenario."""

from __future__ import annotations

import numpy as np
import pytest

from groundfloor.units import KNOT_MPS
from raysim.scenario import load_scenario
from raysim.world import World
from tests.conftest import BASE


@pytest.fixture
def world(write_scenario):
    return World(load_scenario(write_scenario(BASE)))


def test_objects_in_file_order_with_ids_from_zero(world):
    got = [(o.object_id, o.name, o.kind, o.key_path) for o in world.objects]
    assert got == [
        (0, "odin", "ownship", "own_ship"),
        (1, "Iceberg_1", "iceberg", "obstacles[0]"),
        (2, "Buoy_1", "buoy", "obstacles[1]"),
        (3, "research_ship", "ship", "ships[0]"),
        (4, "anchored", "ship", "ships[1]"),
    ]
    assert world.own_ship is world.objects[0]
    assert [o.object_id for o in world.scene_objects()] == [0, 1, 2, 3, 4]


def test_transponders_and_dimensions(world):
    by_name = {o.name: o for o in world.objects}
    assert by_name["research_ship"].ais.mmsi == 257000002
    assert all(by_name[n].ais is None for n in ("odin", "Iceberg_1", "Buoy_1", "anchored"))
    ship = by_name["research_ship"]
    assert (ship.length_m, ship.beam_m) == (100.0, pytest.approx(16.13, abs=0.01))  # resolved default beam
    berg = by_name["Iceberg_1"]
    # a generated berg's above-water part is exactly radius_m from its axis, height_m high
    assert berg.height_m == pytest.approx(8.0)
    assert max(berg.length_m, berg.beam_m) <= 2 * 15.0 + 1e-9


def test_stationary_objects_sit_at_their_positions_on_the_sea(world):
    scenario = world.scenario
    for obstacle, obj in zip(scenario.obstacles, world.objects[1:3]):
        x, y = world.frame.to_local(*obstacle.position)
        pose = obj.motion.poses(np.array([0.0, 3.0]))
        assert pose.position_m == pytest.approx(np.array([[x, y, 0.0]] * 2), abs=1e-6)
        assert obj.motion.velocity_mps(np.array([0.0])) == pytest.approx(np.zeros((1, 3)))


def test_ships_start_at_their_first_waypoint_and_move_at_their_speed(world):
    ship = world.objects[3]
    x0, y0 = world.frame.to_local(*world.scenario.ships[0].waypoints[0])
    assert ship.motion.poses(np.array([0.0])).position_m[0, :2] == pytest.approx([float(x0), float(y0)], abs=1e-6)
    speed = np.hypot(*ship.motion.velocity_mps(np.array([2.0]))[0, :2])
    assert speed == pytest.approx(10 * KNOT_MPS, rel=1e-6)
    anchored = world.objects[4]
    assert np.hypot(*anchored.motion.velocity_mps(np.array([1.0]))[0, :2]) == pytest.approx(0.0, abs=1e-9)


def test_the_origin_is_the_scenarios(world):
    assert world.frame.to_local(BASE["origin"]["lat"], BASE["origin"]["lon"]) == pytest.approx((0.0, 0.0), abs=1e-6)
